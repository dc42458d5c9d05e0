#include "rtsp_credentials.hpp"

#include <sys/stat.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <set>

namespace neuflow::daemon {
namespace {

bool has_control_characters(const std::string& text) {
  for (const char c : text) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7F) return true;
  }
  return false;
}

}  // namespace

std::vector<RtspUser> read_rtsp_credentials(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) {
    throw RtspCredentialsError("rtsp credentials " + file.string() + ": cannot read: " + std::strerror(errno));
  }
  std::vector<RtspUser> users;
  std::set<std::string> names;
  int number = 0;
  const auto fail = [&](const std::string& what) {
    throw RtspCredentialsError("rtsp credentials " + file.string() + ":" + std::to_string(number) + ": " + what);
  };
  for (std::string line; std::getline(in, line);) {
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || line.front() == '#') continue;
    const auto colon = line.find(':');
    if (colon == std::string::npos) fail("expected user:password");
    RtspUser user{line.substr(0, colon), line.substr(colon + 1)};
    if (user.name.empty()) fail("the user name is empty; expected user:password");
    if (user.password.empty()) fail("user '" + user.name + "' has an empty password");
    if (has_control_characters(user.name) || has_control_characters(user.password)) {
      fail("control characters are not allowed in a user name or password");
    }
    if (!names.insert(user.name).second) fail("user '" + user.name + "' is listed twice");
    users.push_back(std::move(user));
  }
  if (in.bad())
    throw RtspCredentialsError("rtsp credentials " + file.string() + ": read error: " + std::strerror(errno));
  if (users.empty()) {
    throw RtspCredentialsError("rtsp credentials " + file.string() +
                               ": no user in the file; expected user:password lines");
  }
  return users;
}

bool readable_by_everyone(const std::filesystem::path& file) {
  struct stat st {};
  return ::stat(file.c_str(), &st) == 0 && (st.st_mode & S_IROTH) != 0;
}

}  // namespace neuflow::daemon
