# The metrics endpoint: the Prometheus text rendering, and the HTTP server over the loopback
# interface (each test runs its own server on a free port, so they can run in parallel).
neuflow_add_test(neuflowd_metrics_tests
  SOURCES
    ${CMAKE_CURRENT_SOURCE_DIR}/metrics_text_test.cpp
    ${CMAKE_CURRENT_SOURCE_DIR}/metrics_server_test.cpp
  LIBS neuflowd_core
  LABELS daemon)
set_target_properties(neuflowd_metrics_tests PROPERTIES NEUFLOW_GLIB_MACROS ON)
