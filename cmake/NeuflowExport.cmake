# The core as a CMake package (the `development` install component, Debian's neuflow-dev):
# `find_package(neuflow)` gives neuflow::model (the network, its sessions and backends) and
# neuflow::flow (flow fields, file formats, colour wheel, metrics). They are static libraries, so
# the libraries they use inside are exported with them (LINK_ONLY) and neuflowConfig.cmake finds
# those dependencies again on the consumer's machine, with this project's own find modules.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(neuflow_exported neuflow_model neuflow_flow neuflow_session_settings neuflow_checkpoint
    neuflow_gpu_devices)
if(TARGET neuflow_volk)
  list(APPEND neuflow_exported neuflow_volk)
endif()
# neuflow::model, not neuflow::neuflow_model: the names the project's own targets use.
foreach(target IN LISTS neuflow_exported)
  string(REGEX REPLACE "^neuflow_" "" export_name "${target}")
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${export_name})
endforeach()

set(NEUFLOW_CMAKE_PACKAGE_DIR "${CMAKE_INSTALL_LIBDIR}/cmake/neuflow" CACHE STRING
    "Where neuflowConfig.cmake is installed (relative: under the install prefix)")
install(TARGETS ${neuflow_exported} EXPORT neuflowTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}/neuflow COMPONENT development
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(DIRECTORY model/include/ flow/include/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
        COMPONENT development FILES_MATCHING PATTERN "*.hpp")
install(EXPORT neuflowTargets NAMESPACE neuflow:: DESTINATION ${NEUFLOW_CMAKE_PACKAGE_DIR}
        COMPONENT development)

configure_package_config_file(cmake/neuflowConfig.cmake.in
  ${CMAKE_CURRENT_BINARY_DIR}/neuflowConfig.cmake INSTALL_DESTINATION ${NEUFLOW_CMAKE_PACKAGE_DIR})
write_basic_package_version_file(${CMAKE_CURRENT_BINARY_DIR}/neuflowConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/neuflowConfig.cmake
              ${CMAKE_CURRENT_BINARY_DIR}/neuflowConfigVersion.cmake
              cmake/FindOneDNN.cmake cmake/FindOpenCV.cmake
        DESTINATION ${NEUFLOW_CMAKE_PACKAGE_DIR} COMPONENT development)
