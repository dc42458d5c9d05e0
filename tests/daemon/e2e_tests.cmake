# neuflowd as a real process: READY/RELOADING/WATCHDOG through a notify socket the test owns,
# flows read from the files sink and from the shared-memory ring by a separate reader process,
# SIGHUP with a changed config, SIGTERM → exit 0 and a playable MP4, a failing source restarted
# while another stream keeps producing, a failing sink cut off, config errors with line numbers.
find_program(NEUFLOW_E2E_PYTHON NAMES python3 HINTS /usr/bin NO_DEFAULT_PATH)
# GStreamer's tools load our plugin, so they are the target's (the arm64 root's in a cross build,
# run through qemu); CMAKE_FIND_ROOT_PATH is empty in a native build.
find_program(GST_LAUNCH gst-launch-1.0 REQUIRED ONLY_CMAKE_FIND_ROOT_PATH)
include(NeuflowGstTestEnv)
neuflow_gst_test_env(e2e_sanitizer_env)   # neuflowd itself is instrumented under NEUFLOW_SANITIZE

if(TARGET neuflow-shm-reader)
  set(shm_reader "$<TARGET_FILE:neuflow-shm-reader>")
else()
  set(shm_reader "neuflow-shm-reader-not-built")
endif()
set(e2e_env
  "NEUFLOWD=$<TARGET_FILE:neuflowd>"
  "NEUFLOW_SHM_READER=${shm_reader}"
  "GST_LAUNCH=${GST_LAUNCH}"
  "GST_PLUGIN_PATH_1_0=$<TARGET_FILE_DIR:gstneuflow>"
  "GST_REGISTRY_1_0=${CMAKE_CURRENT_BINARY_DIR}/e2e-registry.bin"
  ${e2e_sanitizer_env})
if(NEUFLOW_SANITIZE)
  # The registry scan would load the instrumented plugin into GStreamer's uninstrumented
  # gst-plugin-scanner; neuflowd (instrumented) scans in its own process instead.
  list(APPEND e2e_env "GST_REGISTRY_FORK=no" "NEUFLOW_E2E_SANITIZED=1")
endif()

foreach(test_case
    DaemonLifecycle.test_ready_flows_reload_and_clean_stop
    DaemonLifecycle.test_watchdog_and_status
    DaemonVideoOut.test_rtsp_mount_and_rtp_udp_deliver_decodable_h264
    DaemonVideoOut.test_rtsp_credentials_keep_out_who_is_not_listed
    DaemonVideoOut.test_every_segment_of_a_live_video_sink_plays
    DaemonFailures.test_failing_source_restarts_while_other_stream_runs
    DaemonFailures.test_failing_sink_is_cut_off_and_the_stream_goes_on
    DaemonFailures.test_a_sink_failing_while_a_video_sink_prerolls_stalls_nothing
    DaemonFailures.test_a_missing_gpu_restarts_its_stream_while_the_others_run
    DaemonFailures.test_a_lost_gpu_restarts_its_stream_on_a_new_device_while_the_others_run
    CheckConfig.test_valid_config_passes
    CheckConfig.test_errors_name_line_and_exit_78
    CheckConfig.test_unknown_choice_offers_the_closest_value
    CheckConfig.test_a_model_that_is_no_checkpoint_is_an_error
    CheckConfig.test_missing_model_is_a_warning_and_the_stream_waits_for_it
    DaemonReliability.test_missing_camera_and_input_file_leave_the_other_streams_running
    DaemonReliability.test_a_sink_that_cannot_be_built_is_cut_off_at_start
    DaemonReliability.test_a_files_sink_records_its_settings_and_refuses_a_folder_made_otherwise
    DaemonReliability.test_a_display_sink_without_a_display_is_cut_off_and_the_daemon_runs_on
    DaemonReliability.test_a_flood_of_idle_metrics_connections_starves_nothing
    DaemonReliability.test_reload_keeps_counters_and_retention_counts_earlier_files
    DaemonReliability.test_memory_after_alternating_reloads_stays_near_a_fresh_start)
  add_test(NAME daemon.e2e.${test_case}
           COMMAND ${NEUFLOW_E2E_PYTHON} ${CMAKE_CURRENT_SOURCE_DIR}/e2e_test.py -v ${test_case})
  set_tests_properties(daemon.e2e.${test_case} PROPERTIES LABELS "daemon;e2e" ENVIRONMENT "${e2e_env}"
                       TIMEOUT 300 RESOURCE_LOCK neuflowd_e2e)
  if(NEUFLOW_SANITIZE)
    set_tests_properties(daemon.e2e.${test_case} PROPERTIES FIXTURES_REQUIRED neuflowd_e2e_registry)
  endif()
endforeach()

if(NEUFLOW_SANITIZE)
  # A registry scan in neuflowd's own process loads every installed plugin into it. On Ubuntu
  # 22.04 one of them (webrtc, through libnice and GUPnP) links libsoup 2, and libsoup aborts a
  # process that has both (neuflowd's metrics server links libsoup 3). So GStreamer's
  # gst-inspect-1.0, with the sanitizer runtimes preloaded, makes the registry first; neuflowd
  # then finds it up to date and loads only the plugins its streams use, as in a release build.
  find_program(GST_INSPECT gst-inspect-1.0 REQUIRED ONLY_CMAKE_FIND_ROOT_PATH)
  neuflow_gst_tool_env(e2e_scan_env "${CMAKE_CURRENT_BINARY_DIR}/e2e-registry.bin")
  add_test(NAME daemon.e2e.registry COMMAND ${GST_INSPECT} neuflow)
  set_tests_properties(daemon.e2e.registry PROPERTIES LABELS "daemon;e2e" ENVIRONMENT "${e2e_scan_env}"
                       FIXTURES_SETUP neuflowd_e2e_registry RESOURCE_LOCK neuflowd_e2e TIMEOUT 300)
endif()
