# Environments for tests that load the plugin from the build tree.
#   neuflow_gst_test_env(<var> <registry-file>) — for our (instrumented) test executables
#   neuflow_gst_tool_env(<var> <registry-file>) — for GStreamer's own tools (gst-inspect-1.0)
# Under the sanitizers GStreamer must not fork its (uninstrumented) plugin scanner, the
# uninstrumented tools get the sanitizer runtimes preloaded, and LSan ignores what GLib and
# GStreamer keep until exit on purpose (plugins/tests/lsan.supp: their frames only).
function(neuflow_gst_test_env var registry)
  set(env "GST_PLUGIN_PATH_1_0=$<TARGET_FILE_DIR:gstneuflow>" "GST_REGISTRY_1_0=${registry}")
  if(NEUFLOW_SANITIZE)
    list(APPEND env "GST_REGISTRY_FORK=no"
         "LSAN_OPTIONS=suppressions=${PROJECT_SOURCE_DIR}/plugins/tests/lsan.supp:print_suppressions=0:fast_unwind_on_malloc=0")
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
