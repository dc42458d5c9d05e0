// The RTSP users file: what it accepts, and errors that name the file and line.
#include "rtsp_credentials.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <fstream>
#include <string>

#include "config.hpp"
#include "config_test_util.hpp"

namespace neuflow::daemon {
namespace {

using test::has_issue;
using test::issues_of;
using test::TempFolder;

std::filesystem::path write(const TempFolder& folder, const std::string& text) {
  const auto path = folder / "rtsp-users";
  std::ofstream(path) << text;
  return path;
}

std::string error_of(const std::filesystem::path& file) {
  try {
    read_rtsp_credentials(file);
  } catch (const RtspCredentialsError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(RtspCredentials, ReadsUserPasswordLinesSkippingCommentsAndBlankLines) {
  TempFolder folder;
  const auto users = read_rtsp_credentials(write(folder, "# viewers\n\nalice:s3cret:with:colons\r\nbob:pw\n"));
  ASSERT_EQ(users.size(), 2u);
  EXPECT_EQ(users[0].name, "alice");
  EXPECT_EQ(users[0].password, "s3cret:with:colons");
  EXPECT_EQ(users[1].name, "bob");
  EXPECT_EQ(users[1].password, "pw");
}

TEST(RtspCredentials, MistakesNameTheFileAndLine) {
  TempFolder folder;
  EXPECT_NE(error_of(write(folder, "alice:pw\nbob\n")).find("rtsp-users:2: expected user:password"), std::string::npos);
  EXPECT_NE(error_of(write(folder, ":pw\n")).find(":1: the user name is empty"), std::string::npos);
  EXPECT_NE(error_of(write(folder, "alice:\n")).find(":1: user 'alice' has an empty password"), std::string::npos);
  EXPECT_NE(error_of(write(folder, "a:1\na:2\n")).find(":2: user 'a' is listed twice"), std::string::npos);
  EXPECT_NE(error_of(write(folder, "# nobody\n")).find("no user in the file"), std::string::npos);
  EXPECT_NE(error_of(folder / "missing").find("cannot read"), std::string::npos);
}

TEST(RtspCredentials, AWorldReadableFileIsNoticed) {
  TempFolder folder;
  const auto path = write(folder, "a:b\n");
  ::chmod(path.c_str(), 0600);
  EXPECT_FALSE(readable_by_everyone(path));
  ::chmod(path.c_str(), 0644);
  EXPECT_TRUE(readable_by_everyone(path));
}

const std::string kRtspStream = R"(
[[stream]]
name = "s"
source = { type = "test" }
flow = { model = "/m.pth" }
sink = [ { type = "video", rtsp = "/s" } ]
)";

TEST(RtspConfig, ListensOnLoopbackByDefaultAndTakesCredentialsRelativeToTheConfig) {
  const Config c = parse_config("[rtsp]\ncredentials = \"rtsp-users\"\nauth = \"basic\"\n" + kRtspStream,
                                "/etc/neuflow/n.toml", ConfigChecks::file_only);
  ASSERT_TRUE(c.rtsp);
  EXPECT_EQ(c.rtsp->address, "127.0.0.1");
  EXPECT_EQ(c.rtsp->port, 8554);
  EXPECT_EQ(c.rtsp->credentials, "/etc/neuflow/rtsp-users");
  EXPECT_EQ(c.rtsp->auth, "basic");
  const Config d = parse_config("[rtsp]\ncredentials = \"/u\"\n" + kRtspStream, "/n.toml", ConfigChecks::file_only);
  EXPECT_EQ(d.rtsp->auth, "digest");
}

TEST(RtspConfig, AuthWithoutCredentialsAndUnknownMethodsAreErrors) {
  EXPECT_TRUE(has_issue(issues_of("[rtsp]\nauth = \"basic\"\n" + kRtspStream), 2, 0, "auth: needs credentials"));
  EXPECT_TRUE(has_issue(issues_of("[rtsp]\ncredentials = \"/u\"\nauth = \"none\"\n" + kRtspStream), 3, 8,
                        "auth: expected one of \"digest\" or \"basic\""));
}

}  // namespace
}  // namespace neuflow::daemon
