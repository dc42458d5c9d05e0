// Placeholder: the config loader is being written.
#include "config.hpp"
