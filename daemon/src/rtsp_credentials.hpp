#pragma once
// The users allowed to watch the RTSP mounts, read from the file that [rtsp] credentials names:
// one `user:password` per line; blank lines and lines starting with '#' are ignored. The file
// is read at start and at every reload (SIGHUP), so users are added or removed without a
// restart. Passwords are kept only in memory and never logged.
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

namespace neuflow::daemon {

struct RtspUser {
  std::string name;
  std::string password;
};

class RtspCredentialsError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Throws RtspCredentialsError naming the file and line: unreadable file, a line without ':',
// an empty user or password, a user listed twice, a user name with ':' or control characters,
// or no user at all.
std::vector<RtspUser> read_rtsp_credentials(const std::filesystem::path& file);

// True when the file's mode lets every user of the machine read it (worth a warning).
bool readable_by_everyone(const std::filesystem::path& file);

}  // namespace neuflow::daemon
