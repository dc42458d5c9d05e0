# neuflowd's config loader.
#   neuflowd_config_tests: the file on its own (syntax, keys, types, ranges, names, paths) and
#     the shipped examples in config/; needs nothing from the machine.
#   neuflowd_config_machine_tests: the checks against this machine (files, devices, folders,
#     GStreamer elements). Its main (tests/plugins/gst_test_main.cpp) calls gst_init and loads
#     the neuflow plugin from this build tree, so the element checks find it uninstalled.
neuflow_add_test(neuflowd_config_tests SOURCES config_test.cpp config_text_test.cpp rtsp_credentials_test.cpp
                 LIBS neuflowd_core neuflow::flow_ring LABELS daemon)
target_compile_definitions(neuflowd_config_tests PRIVATE NEUFLOW_CONFIG_DIR="${PROJECT_SOURCE_DIR}/config")

if(TARGET neuflow_gst_test_main)
  add_executable(neuflowd_config_machine_tests config_environment_test.cpp)
  target_link_libraries(neuflowd_config_machine_tests PRIVATE neuflowd_core neuflow_gst_test_main
                        neuflow_test_support neuflow_test_checkpoints GTest::gtest neuflow::options)
  set_target_properties(neuflowd_config_machine_tests PROPERTIES NEUFLOW_GLIB_MACROS ON)
  include(NeuflowGstTestEnv)
  neuflow_gst_test_env(neuflowd_config_env)
  set(neuflowd_config_test_properties LABELS "daemon")
  if(neuflowd_config_env)
    list(APPEND neuflowd_config_test_properties ENVIRONMENT "${neuflowd_config_env}")
  endif()
  gtest_discover_tests(neuflowd_config_machine_tests PROPERTIES ${neuflowd_config_test_properties}
                       DISCOVERY_TIMEOUT 60)
else()
  message(STATUS "neuflowd config machine tests skipped: they need the GStreamer plugin (NEUFLOW_BUILD_PLUGIN)")
endif()
