# Environments for tests that load the plugin from the build tree.
#   neuflow_gst_test_env(<var>) — for our (instrumented) gtest executables, whose main()
#     (tests/plugins/gst_test_main.cpp) sets the plugin path and registry itself: under the
#     sanitizers, LSan ignores what GLib keeps until exit on purpose (tests/plugins/lsan.supp,
#     their frames only; GLib has no frame pointers, hence the slow unwinder). One variable,
#     since gtest_discover_tests splits lists.
#   neuflow_gst_tool_env(<var> <registry-file>) — for GStreamer's own tools (gst-inspect-1.0):
#     the plugin path and registry, and under the sanitizers their runtimes preloaded, as
#     the tools are not instrumented.
function(neuflow_gst_test_env var)
  set(env "")
  if(NEUFLOW_SANITIZE)
    set(env "LSAN_OPTIONS=suppressions=${PROJECT_SOURCE_DIR}/tests/plugins/lsan.supp:print_suppressions=0:fast_unwind_on_malloc=0")
  endif()
  set(${var} "${env}" PARENT_SCOPE)
endfunction()

function(neuflow_gst_tool_env var registry)
  set(env "GST_PLUGIN_PATH_1_0=$<TARGET_FILE_DIR:gstneuflow>" "GST_REGISTRY_1_0=${registry}")
  if(NEUFLOW_SANITIZE)
    execute_process(COMMAND ${CMAKE_CXX_COMPILER} -print-file-name=libasan.so
                    OUTPUT_VARIABLE libasan OUTPUT_STRIP_TRAILING_WHITESPACE)
    execute_process(COMMAND ${CMAKE_CXX_COMPILER} -print-file-name=libubsan.so
                    OUTPUT_VARIABLE libubsan OUTPUT_STRIP_TRAILING_WHITESPACE)
    list(APPEND env "LD_PRELOAD=${libasan}:${libubsan}" "ASAN_OPTIONS=detect_leaks=0")
  endif()
  set(${var} "${env}" PARENT_SCOPE)
endfunction()
