// neuflowd's config checked against the machine (ConfigChecks::all): files, devices, output
// folders and GStreamer elements. The test main loads the neuflow plugin from this build tree;
// a fake inventory stands in for machines that lack other plugins.
#include "config_environment.hpp"

#include <gst/gst.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <toml++/toml.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <set>
#include <string>

#include "checkpoint_builder.hpp"
#include "config.hpp"
#include "config_read.hpp"
#include "config_test_util.hpp"
#include "neuflow/model/gpu_devices.hpp"

namespace neuflow::daemon {
namespace {

using test::has_issue;
using test::issues_of;
using test::TempFolder;
namespace fs = std::filesystem;

// Every element and URI scheme installed except those named.
GstInventory inventory_without(const std::set<std::string>& elements, const std::set<std::string>& schemes = {}) {
  return GstInventory{[elements](const std::string& f) { return !elements.contains(f); },
                      [schemes](const std::string& s) { return !schemes.contains(s); }};
}

// The machine's issues for a config whose file itself is valid.
std::vector<ConfigIssue> machine_issues(const std::string& text, const GstInventory& gstreamer,
                                        const fs::path& file = test::kConfigFile) {
  const toml::table root = toml::parse(std::string_view(text), std::string_view(file.string()));
  Issues issues(file);
  const ReadResult read = read_config(root, file, issues);
  EXPECT_TRUE(issues.empty()) << test::listed(issues.take_sorted());
  check_machine(read.needs, gstreamer, issues);
  return issues.take_sorted();
}

void write_file(const fs::path& path, const std::string& content = "x") { std::ofstream(path) << content; }

// A small file with NeuFlow-V2's tensors and shapes, which passes the checkpoint check.
void write_model(const fs::path& path) { neuflow::test::fake_neuflow_checkpoint().write(path); }

bool running_as_root() { return ::geteuid() == 0; }

// The checks run as in a (Wayland) desktop session, so the display sinks these tests use as the
// simplest sink need only waylandsink (gstreamer1.0-plugins-bad, which the build installs); the
// test of a machine without a display unsets it.
class DesktopSession : public ::testing::Environment {
 public:
  void SetUp() override {
    unsetenv("DISPLAY");
    setenv("WAYLAND_DISPLAY", "wayland-neuflow-test", 1);
  }
};
const ::testing::Environment* const kDesktopSession = ::testing::AddGlobalTestEnvironment(new DesktopSession);

// Sets or unsets an environment variable for one scope.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const char* value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old;
    if (value) {
      setenv(name, value, 1);
    } else {
      unsetenv(name);
    }
  }
  ~ScopedEnv() {
    if (old_) {
      setenv(name_, old_->c_str(), 1);
    } else {
      unsetenv(name_);
    }
  }
  ScopedEnv(const ScopedEnv&) = delete;
  ScopedEnv& operator=(const ScopedEnv&) = delete;

 private:
  const char* name_;
  std::optional<std::string> old_;
};

// A stream with the given source and sinks, and a model path.
std::string stream(const std::string& source, const std::string& model, const std::string& sinks) {
  return "[[stream]]\nname = \"s\"\nsource = " + source + "\nflow = { model = \"" + model + "\" }\n" + sinks;
}

TEST(ConfigMachine, PluginElementsAreFoundFromTheBuildTree) {
  const GstInventory installed = installed_gstreamer();
  for (const char* element : {"neuflow", "neuflowviz", "neuflowsink", "videotestsrc", "videoconvert"}) {
    EXPECT_TRUE(installed.has_element(element)) << element;
  }
  EXPECT_FALSE(installed.has_element("neuflow-no-such-element"));
  EXPECT_TRUE(installed.reads_uri_scheme("file"));
  EXPECT_FALSE(installed.reads_uri_scheme("neuflow-no-such-scheme"));
}

TEST(ConfigMachine, AValidSetupPasses) {
  TempFolder folder;
  fs::create_directory(folder / "models");
  write_model(folder / "models/m.pth");
  write_file(folder / "in.mp4");
  const std::string text = stream("{ type = \"uri\", path = \"in.mp4\" }", "models/m.pth", R"(
  [[stream.sink]]
  type = "files"
  directory = "out/flow/deeper"
  [[stream.sink]]
  type = "video"
  file = "out/viz/flow-%05d.mkv"
  [[stream.sink]]
  type = "display"
[[stream]]
name = "t"
source = { type = "test" }
flow = { model = "models/m.pth" }
sink = [ { type = "video", udp = "127.0.0.1:5000" } ]
)");
  const Config c = parse_config(text, folder / "neuflowd.toml", ConfigChecks::all);
  EXPECT_EQ(c.streams[0].flow.stage.model, folder / "models/m.pth");
  // Checking creates nothing.
  EXPECT_FALSE(fs::exists(folder / "out"));
}

TEST(ConfigMachine, ModelMustBeAReadableFile) {
  TempFolder folder;
  const fs::path file = folder / "neuflowd.toml";
  const std::string sink = "sink = [ { type = \"display\" } ]\n";
  const auto all = inventory_without({});

  auto issues = machine_issues(stream("{ type = \"test\" }", "models/missing.pth", sink), all, file);
  ASSERT_EQ(issues.size(), 1u) << test::listed(issues);
  EXPECT_TRUE(has_issue(issues, 4, 18,
                        "model: \"" + (folder / "models/missing.pth").string() +
                            "\" (\"models/missing.pth\" relative to the config file's folder) does not exist"));

  fs::create_directory(folder / "folder.pth");
  issues = machine_issues(stream("{ type = \"test\" }", (folder / "folder.pth").string(), sink), all, file);
  EXPECT_TRUE(has_issue(issues, 4, 18, "is a folder, expected a file"));

  if (!running_as_root()) {
    write_file(folder / "locked.pth");
    fs::permissions(folder / "locked.pth", fs::perms::none);
    issues = machine_issues(stream("{ type = \"test\" }", "locked.pth", sink), all, file);
    EXPECT_TRUE(has_issue(issues, 4, 18, "cannot be read by this user: Permission denied"));
  }
}

// A file that is there but is no NeuFlow-V2 checkpoint will not become one by waiting: an
// error (--check-config exits 78), found from the header alone.
TEST(ConfigMachine, ModelMustBeANeuflowV2Checkpoint) {
  TempFolder folder;
  const fs::path file = folder / "neuflowd.toml";
  const std::string sink = "sink = [ { type = \"display\" } ]\n";
  const auto all = inventory_without({});
  write_file(folder / "passwd", "root:x:0:0:root:/root:/bin/bash\n");
  auto issues = machine_issues(stream("{ type = \"test\" }", "passwd", sink), all, file);
  ASSERT_EQ(issues.size(), 1u) << test::listed(issues);
  EXPECT_TRUE(has_issue(issues, 4, 18, "is not a NeuFlow-V2 checkpoint: not a PyTorch checkpoint"));

  auto other = neuflow::test::fake_neuflow_checkpoint();
  other.tensors.pop_back();  // upsample_s8.conv3.bias missing
  other.write(folder / "other.pth");
  issues = machine_issues(stream("{ type = \"test\" }", "other.pth", sink), all, file);
  ASSERT_EQ(issues.size(), 1u) << test::listed(issues);
  EXPECT_TRUE(has_issue(issues, 4, 18, "is not a NeuFlow-V2 checkpoint: missing tensor 'upsample_s8.conv3.bias'"));

  // Through the loader: an error, not a warning.
  write_file(folder / "passwd.toml", stream("{ type = \"test\" }", "passwd", sink));
  try {
    load_config(folder / "passwd.toml");
    ADD_FAILURE() << "a config whose model is no checkpoint loaded";
  } catch (const ConfigError& e) {
    std::size_t errors = 0;
    for (const auto& issue : e.issues()) errors += issue.is_warning() ? 0 : 1;
    EXPECT_EQ(errors, 1u) << e.what();
  }
}

TEST(ConfigMachine, V4l2DeviceMustBeACharacterDevice) {
  TempFolder folder;
  write_model(folder / "m.pth");
  write_file(folder / "video9");
  const std::string model = (folder / "m.pth").string();
  const std::string sink = "sink = [ { type = \"display\" } ]\n";
  const auto all = inventory_without({});

  auto issues =
      machine_issues(stream("{ type = \"v4l2\", device = \"/dev/neuflow-test-no-video\" }", model, sink), all);
  ASSERT_EQ(issues.size(), 1u) << test::listed(issues);
  EXPECT_TRUE(has_issue(issues, 3, 36,
                        "device: \"/dev/neuflow-test-no-video\" does not exist: is the camera "
                        "connected? (ls /dev/video*)"));

  issues = machine_issues(stream("{ type = \"v4l2\", device = \"" + (folder / "video9").string() + "\" }", model, sink),
                          all);
  EXPECT_TRUE(has_issue(issues, 3, 36, "is not a device node; expected a V4L2 device like /dev/video0"));

  // /dev/null is a character device anyone may open: the node check passes.
  EXPECT_TRUE(machine_issues(stream("{ type = \"v4l2\", device = \"/dev/null\" }", model, sink), all).empty());

  // Without `device` the default /dev/video0 is checked, reported at the source table.
  if (!fs::exists("/dev/video0")) {
    issues = machine_issues(stream("{ type = \"v4l2\" }", model, sink), all);
    EXPECT_TRUE(has_issue(issues, 3, 10, "device: \"/dev/video0\" does not exist"));
  }
}

TEST(ConfigMachine, InputFilesMustExist) {
  TempFolder folder;
  write_model(folder / "m.pth");
  const std::string model = (folder / "m.pth").string();
  const std::string sink = "sink = [ { type = \"display\" } ]\n";
  const auto all = inventory_without({});
  const fs::path file = folder / "neuflowd.toml";

  auto issues =
      machine_issues(stream("{ type = \"uri\", uri = \"file:///neuflow-test/none.mp4\" }", model, sink), all, file);
  ASSERT_EQ(issues.size(), 1u) << test::listed(issues);
  EXPECT_TRUE(has_issue(issues, 3, 32, "uri: \"/neuflow-test/none.mp4\" does not exist"));

  issues = machine_issues(stream("{ type = \"uri\", path = \"clips/none.mp4\" }", model, sink), all, file);
  EXPECT_TRUE(has_issue(issues, 3, 33,
                        "path: \"" + (folder / "clips/none.mp4").string() +
                            "\" (\"clips/none.mp4\" relative to the config file's folder) does not "
                            "exist"));

  // Network sources are only checked for a GStreamer element that reads their scheme.
  EXPECT_TRUE(
      machine_issues(stream("{ type = \"uri\", uri = \"rtsp://camera.invalid/s\" }", model, sink), all).empty());
}

TEST(ConfigMachine, OutputFoldersMustExistOrBeCreatable) {
  TempFolder folder;
  write_model(folder / "m.pth");
  write_file(folder / "plain-file");
  const std::string model = (folder / "m.pth").string();
  const auto all = inventory_without({});
  const fs::path file = folder / "neuflowd.toml";
  const auto sinks = [&](const std::string& files_dir, const std::string& video_file) {
    return stream("{ type = \"test\" }", model,
                  "sink = [ { type = \"files\", directory = \"" + files_dir +
                      "\" },\n         { type = \"video\", file = \"" + video_file + "\" } ]\n");
  };

  // Folders that do not exist yet under a writable one are fine.
  EXPECT_TRUE(machine_issues(sinks("new/flow", "new/viz/a.mp4"), all, file).empty());

  auto issues = machine_issues(sinks("plain-file/flow", "plain-file/sub/a.mp4"), all, file);
  ASSERT_EQ(issues.size(), 2u) << test::listed(issues);
  EXPECT_TRUE(has_issue(issues, 5, 40,
                        "directory: \"" + (folder / "plain-file/flow").string() +
                            "\" (\"plain-file/flow\" relative to the config file's folder) cannot be "
                            "created: \"" +
                            (folder / "plain-file").string() + "\" is not a folder"));
  EXPECT_TRUE(has_issue(issues, 6, 35,
                        "file: \"" + (folder / "plain-file/sub").string() +
                            "\" (\"plain-file/sub\" "
                            "relative to the config file's folder) cannot be created"));

  issues = machine_issues(sinks("plain-file", "plain-file/a.mp4"), all, file);
  ASSERT_EQ(issues.size(), 2u) << test::listed(issues);
  EXPECT_TRUE(has_issue(issues, 5, 40, "exists but is not a folder"));
  EXPECT_TRUE(has_issue(issues, 6, 35,
                        "file: \"" + (folder / "plain-file").string() +
                            "\" (\"plain-file\" relative "
                            "to the config file's folder) exists but is not a folder"));

  if (!running_as_root()) {
    fs::create_directory(folder / "locked");
    fs::permissions(folder / "locked", fs::perms::owner_read | fs::perms::owner_exec);
    issues = machine_issues(sinks("locked/flow", "locked/a.mp4"), all, file);
    ASSERT_EQ(issues.size(), 2u) << test::listed(issues);
    EXPECT_TRUE(has_issue(
        issues, 5, 40,
        "does not exist and cannot be created: \"" + (folder / "locked").string() + "\" is not writable by this user"));
    EXPECT_TRUE(has_issue(issues, 6, 35, "is not writable by this user"));
  }
}

TEST(ConfigMachine, MissingNeuflowPluginIsReportedOnceWithWhatToDo) {
  const std::string text = stream("{ type = \"test\" }", "/dev/null",
                                  "sink = [ { type = \"files\", directory = \"/tmp\" }, { type = \"display\" } ]\n") +
                           "[[stream]]\nname = \"t\"\nsource = { type = \"test\" }\nflow = { model = \"/dev/null\" }\n"
                           "sink = [ { type = \"display\" } ]\n";
  const auto issues = machine_issues(text, inventory_without({"neuflow", "neuflowviz", "neuflowsink"}));
  // The plugin once, and /dev/null as the model of both streams.
  ASSERT_EQ(issues.size(), 3u) << test::listed(issues);
  EXPECT_TRUE(has_issue(issues, 4, 8,
                        "the neuflow GStreamer plugin (libgstneuflow.so), needed by stream 's', was "
                        "not found: install it (cmake --install) or set GST_PLUGIN_PATH to the folder "
                        "that holds libgstneuflow.so"));
  EXPECT_TRUE(has_issue(issues, 4, 18, "is not a regular file"));
}

TEST(ConfigMachine, MissingElementsNameTheirUsersAndPackage) {
  TempFolder folder;
  write_model(folder / "m.pth");
  const std::string text = stream("{ type = \"libcamera\" }", (folder / "m.pth").string(),
                                  "sink = [ { type = \"video\", udp = \"127.0.0.1:5000\" },\n"
                                  "         { type = \"video\", name = \"rec\", file = \"" +
                                      (folder / "v.mp4").string() +
                                      "\" },\n"
                                      "         { type = \"shm\", shm-name = \"/neuflow-test\" } ]\n");
  const auto issues = machine_issues(text, inventory_without({"x264enc", "libcamerasrc", "neuflowshmsink"}));
  ASSERT_EQ(issues.size(), 3u) << test::listed(issues);
  EXPECT_TRUE(has_issue(issues, 3, 10,
                        "GStreamer element 'libcamerasrc', needed by the libcamera source of stream "
                        "'s', is not installed (Debian: apt install gstreamer1.0-libcamera)"));
  EXPECT_TRUE(has_issue(issues, 5, 10,
                        "GStreamer element 'x264enc', needed by the video sink 'video-0' of stream "
                        "'s' (and 1 more), is not installed (Debian: apt install "
                        "gstreamer1.0-plugins-ugly)"));
  EXPECT_TRUE(has_issue(issues, 7, 10,
                        "GStreamer element 'neuflowshmsink', needed by the shm sink 'shm-2' of "
                        "stream 's', is not in the installed neuflow plugin, which is older than this "
                        "neuflowd"));
}

TEST(ConfigMachine, UriSchemesNeedAnElementThatReadsThem) {
  const std::string text = stream("{ type = \"uri\", uri = \"rtsp://camera.invalid/s\" }", "/dev/null",
                                  "sink = [ { type = \"display\" } ]\n");
  const auto issues = machine_issues(text, inventory_without({}, {"rtsp"}));
  EXPECT_TRUE(has_issue(issues, 3, 32,
                        "uri: no installed GStreamer element reads \"rtsp://\" URIs, needed by the "
                        "uri source of stream 's' (Debian: apt install gstreamer1.0-plugins-good)"));
}

TEST(ConfigMachine, FileAndMachineIssuesComeTogetherInFileOrder) {
  TempFolder folder;
  const auto issues = issues_of(R"([daemon]
colour = "red"
[[stream]]
name = "s"
source = { type = "v4l2", device = "/dev/neuflow-test-no-video" }
flow = { model = "missing.pth", iters-s8 = 100 }
sink = [ { type = "display" } ]
)",
                                ConfigChecks::all, folder / "neuflowd.toml");
  ASSERT_EQ(issues.size(), 4u) << test::listed(issues);
  EXPECT_TRUE(has_issue(issues, 2, 1, "unknown key 'colour'"));
  EXPECT_TRUE(has_issue(issues, 5, 36, "does not exist: is the camera connected?"));
  EXPECT_TRUE(has_issue(issues, 6, 18, "model: \"" + (folder / "missing.pth").string() + "\""));
  EXPECT_TRUE(has_issue(issues, 6, 44, "iters-s8: expected an integer 0..64, got 100"));
}

// backend = "vulkan" needs Vulkan and the device; the issue points at the key. backend = "auto"
// needs neither (it falls back to the CPU).
// Without a graphical session a display sink would be cut off at start: a warning that says so,
// at the sink's type; with one, nothing.
TEST(ConfigMachine, ADisplaySinkWithoutADisplayIsAWarning) {
  TempFolder folder;
  write_model(folder / "m.pth");
  const fs::path file = folder / "neuflowd.toml";
  const std::string text =
      stream("{ type = \"test\" }", "m.pth", "sink = [ { type = \"display\", name = \"screen\" } ]\n");
  EXPECT_TRUE(machine_issues(text, inventory_without({}), file).empty());
  const ScopedEnv no_x11("DISPLAY", nullptr), no_wayland("WAYLAND_DISPLAY", nullptr);
  const auto issues = machine_issues(text, inventory_without({}), file);
  ASSERT_EQ(issues.size(), 1u) << test::listed(issues);
  EXPECT_TRUE(has_issue(issues, 5, 19,
                        "type: the display sink 'screen' of stream 's' shows a window, but there is no display to "
                        "open a window on (neither WAYLAND_DISPLAY nor DISPLAY is set"))
      << test::listed(issues);
}

TEST(ConfigMachine, AVulkanDeviceMustExist) {
  TempFolder folder;
  write_model(folder / "m.pth");
  const fs::path file = folder / "neuflowd.toml";
  const auto all = inventory_without({});
  const auto with_flow = [&](const std::string& flow) {
    return "[[stream]]\nname = \"s\"\nsource = { type = \"test\" }\nflow = { model = \"m.pth\", " + flow +
           " }\nsink = [ { type = \"display\" } ]\n";
  };
  EXPECT_TRUE(machine_issues(with_flow("backend = \"auto\", device = 63"), all, file).empty());
  EXPECT_TRUE(machine_issues(with_flow("backend = \"cpu\""), all, file).empty());
  bool have_vulkan = false;
  std::size_t devices = 0;
  try {
    devices = model::list_gpu_devices().size();
    have_vulkan = devices > 0;
  } catch (const model::BackendError&) {
  }
  const auto issues = machine_issues(with_flow("backend = \"vulkan\", device = 63"), all, file);
  ASSERT_EQ(issues.size(), 1u) << test::listed(issues);
  if (have_vulkan) {
    EXPECT_TRUE(has_issue(
        issues, 4, 56, "device: stream 's' asks for Vulkan device 63, but this machine has " + std::to_string(devices)))
        << test::listed(issues);
    EXPECT_TRUE(machine_issues(with_flow("backend = \"vulkan\", device = 0"), all, file).empty());
  } else {
    EXPECT_TRUE(has_issue(issues, 4, 56, "backend: stream 's' runs on Vulkan, but")) << test::listed(issues);
  }
}

}  // namespace
}  // namespace neuflow::daemon
