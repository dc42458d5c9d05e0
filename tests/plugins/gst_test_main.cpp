// main() of the element tests: loads the plugin from the build tree, whatever the
// environment says, and keeps the plugin registry inside the build directory.
#include <gst/gst.h>
#include <gtest/gtest.h>

namespace {

class GstEnvironment : public ::testing::Environment {
 public:
  // Only when tests run (not for --gtest_list_tests at build time): the first gst_init in a
  // fresh build directory scans every installed plugin.
  void SetUp() override { gst_init(nullptr, nullptr); }
};

}  // namespace

int main(int argc, char **argv) {
  ::testing::InitGoogleTest(&argc, argv);
  g_setenv("GST_PLUGIN_PATH_1_0", NEUFLOW_GST_PLUGIN_DIR, TRUE);
  g_setenv("GST_REGISTRY_1_0", NEUFLOW_GST_REGISTRY, TRUE);
#ifdef NEUFLOW_GST_NO_REGISTRY_FORK
  // Sanitized builds: the plugin scanner helper is not instrumented and cannot load our
  // instrumented plugin, so scan in this process.
  g_setenv("GST_REGISTRY_FORK", "no", TRUE);
#endif
  ::testing::AddGlobalTestEnvironment(new GstEnvironment);
  return RUN_ALL_TESTS();
}
