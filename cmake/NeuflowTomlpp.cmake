# toml++ (3.x), which neuflowd reads its config with and `neuflow convert` its folders' records: Debian 12's libtomlplusplus-dev (a shared
# library, found with pkg-config), or, where it is not packaged (Ubuntu 22.04, JetPack 6), the
# header-only library from its source tree: -DTOMLPP_INCLUDE_DIR=<tomlplusplus>/include.
# Defines neuflow::tomlplusplus, or stops with what to do.
if(TARGET neuflow::tomlplusplus)
  return()
endif()
set(TOMLPP_INCLUDE_DIR "" CACHE PATH "toml++'s include/ folder (header-only use), when it is not installed")
find_package(PkgConfig REQUIRED)
if(NOT TOMLPP_INCLUDE_DIR)
  pkg_check_modules(TOMLPP QUIET IMPORTED_TARGET tomlplusplus>=3)
endif()
if(TOMLPP_FOUND)
  add_library(neuflow::tomlplusplus ALIAS PkgConfig::TOMLPP)
  message(STATUS "toml++ ${TOMLPP_VERSION}: the installed library")
  return()
endif()
if(NOT TOMLPP_INCLUDE_DIR)
  find_path(TOMLPP_INCLUDE_DIR toml++/toml.h)
endif()
if(TOMLPP_INCLUDE_DIR AND EXISTS "${TOMLPP_INCLUDE_DIR}/toml++/toml.h")
  add_library(neuflow_tomlplusplus INTERFACE)
  target_include_directories(neuflow_tomlplusplus SYSTEM INTERFACE "${TOMLPP_INCLUDE_DIR}")
  target_compile_definitions(neuflow_tomlplusplus INTERFACE TOML_HEADER_ONLY=1)
  add_library(neuflow::tomlplusplus ALIAS neuflow_tomlplusplus)
  message(STATUS "toml++: header-only from ${TOMLPP_INCLUDE_DIR}")
  return()
endif()
message(FATAL_ERROR
  "toml++ 3.x (the TOML parser neuflowd reads its config with) was not found.\n"
  "  Debian 12: sudo apt install libtomlplusplus-dev\n"
  "  Ubuntu 22.04 / JetPack 6 (not packaged there; it is header-only):\n"
  "    git clone --depth 1 --branch v3.3.0 https://github.com/marzer/tomlplusplus\n"
  "    cmake ... -DTOMLPP_INCLUDE_DIR=$PWD/tomlplusplus/include")
