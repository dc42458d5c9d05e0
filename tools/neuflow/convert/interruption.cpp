#include "convert/interruption.hpp"

#include <signal.h>
#include <sys/types.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <string>
#include <system_error>

namespace neuflow::cli {

namespace {

volatile std::sig_atomic_t g_signal = 0;

extern "C" void on_signal(int signal) { g_signal = signal; }

struct sigaction g_previous_int {
}, g_previous_term{};

// The writer's process id in a temporary file's name: the digits after ".partial-".
pid_t writer_of(const std::string& name) {
  const auto at = name.find(".partial-");
  if (at == std::string::npos) return 0;
  const char* digits = name.c_str() + at + 9;
  char* end = nullptr;
  const long pid = std::strtol(digits, &end, 10);
  return end == digits || pid <= 0 ? 0 : static_cast<pid_t>(pid);
}

bool running(pid_t pid) { return ::kill(pid, 0) == 0 || errno == EPERM; }

}  // namespace

InterruptionHandler::InterruptionHandler() {
  g_signal = 0;
  struct sigaction action {};
  action.sa_handler = on_signal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESETHAND;  // the second signal takes the default action: the process ends
  ::sigaction(SIGINT, &action, &g_previous_int);
  ::sigaction(SIGTERM, &action, &g_previous_term);
}

InterruptionHandler::~InterruptionHandler() {
  ::sigaction(SIGINT, &g_previous_int, nullptr);
  ::sigaction(SIGTERM, &g_previous_term, nullptr);
}

int interruption_signal() { return g_signal; }

void remove_stale_partials(const std::filesystem::path& folder) {
  std::error_code ec;
  for (std::filesystem::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    const pid_t pid = writer_of(name);
    if (pid > 0 && pid != ::getpid() && !running(pid)) {
      std::error_code ignored;
      std::filesystem::remove(it->path(), ignored);
    }
  }
}

}  // namespace neuflow::cli
