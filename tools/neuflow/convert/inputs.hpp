#pragma once
// What `neuflow convert` was asked to convert: each command-line input classified (image
// pair, folder of frames, video) and given the name of its output sub-folder.
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "convert/input_error.hpp"

namespace neuflow::cli {

enum class InputKind { image_pair, image_folder, video };

struct InputSpec {
  InputKind kind = InputKind::video;
  // image_pair: the two images; image_folder: the folder; video: the file or URI.
  std::vector<std::string> paths;
  std::string label;                   // how messages name the input: as given on the command line
  std::string output_name;             // its sub-folder of the output folder, unique among the inputs
  std::optional<InputError> rejected;  // set when the input cannot be converted at all
};

// True for the extensions OpenCV reads as images (.png, .jpg, .jpeg, .bmp, .tif, .tiff,
// .webp, .ppm, .pgm, .pnm), case-insensitively.
bool has_image_extension(const std::string& path);

// Classifies the inputs, the `pairs` first, then `positional` in order: each `pairs` entry
// is an image pair; among `positional`, a folder is a sequence of frames, a URI or another existing file a video,
// and exactly two image files together form a pair (any other image file on its own is
// rejected, as is a path that does not exist).
//
// Output names: a folder or video is named after its file name without extension, a pair
// `<first stem>_<second stem>`; a name taken by an earlier input gets `_2`, `_3`… so the
// same command line always gives the same names (which --resume relies on).
std::vector<InputSpec> plan_inputs(const std::vector<std::string>& positional,
                                   const std::vector<std::pair<std::string, std::string>>& pairs);

}  // namespace neuflow::cli
