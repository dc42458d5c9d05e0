# Debian packages through CPack (`cpack -G DEB` in a build folder; scripts/build-deb.sh):
#   neuflow      the `runtime` install component: the tools, neuflowd, the GStreamer plugin, the
#                systemd units, the sysusers.d file, the example configs in /etc/neuflow/examples
#                (conffiles) and the docs;
#   neuflow-dev  the `development` component: the core's headers and static libraries and the
#                CMake package (find_package(neuflow), cmake/NeuflowExport.cmake);
#   python3-neuflow  the `python` component (NEUFLOW_BUILD_PYTHON): `import neuflow` in
#                /usr/lib/python3/dist-packages, the core linked into it.
# The package's prefix is /usr whatever the build folder's CMAKE_INSTALL_PREFIX: CPack installs
# with DESTDIR and CMAKE_INSTALL_PREFIX=/usr, so the install-time paths (the units' ExecStart,
# /etc for the configs) are the package's.
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME neuflow)
set(CPACK_PACKAGE_VENDOR "neuflow")
set(CPACK_PACKAGE_CONTACT "neuflow maintainers <neuflow@localhost>")
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "${PROJECT_DESCRIPTION}")
set(CPACK_SET_DESTDIR ON)
set(CPACK_INSTALL_PREFIX /usr)
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_STRIP_FILES ON)
set(CPACK_PACKAGE_DIRECTORY ${CMAKE_BINARY_DIR}/packages)

set(CPACK_DEB_COMPONENT_INSTALL ON)
set(CPACK_COMPONENTS_ALL runtime development)
if(NEUFLOW_BUILD_PYTHON AND TARGET neuflow_python)
  list(APPEND CPACK_COMPONENTS_ALL python)
endif()
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)   # neuflow_0.1.0-1_amd64.deb
set(CPACK_DEBIAN_PACKAGE_RELEASE 1)
set(neuflow_deb_version "${PROJECT_VERSION}-${CPACK_DEBIAN_PACKAGE_RELEASE}")
set(CPACK_DEBIAN_PACKAGE_SECTION video)
set(CPACK_DEBIAN_PACKAGE_HOMEPAGE "file:///usr/share/doc/neuflow/README.md")
if(CMAKE_CROSSCOMPILING)
  # dpkg --print-architecture (CPack's default) names the build machine's architecture.
  if(CMAKE_SYSTEM_PROCESSOR MATCHES "^(aarch64|arm64)$")
    set(CPACK_DEBIAN_PACKAGE_ARCHITECTURE arm64)
  else()
    set(CPACK_DEBIAN_PACKAGE_ARCHITECTURE ${CMAKE_SYSTEM_PROCESSOR})
  endif()
endif()

# The libraries the programs link come from dpkg-shlibdeps, which reads this machine's
# packages, so a package built on Debian 12 names Debian 12's libraries and one built on a Jetson
# (Ubuntu 22.04) Ubuntu's. A cross build has no package database of its target to read: it is
# given the list (scripts/check-arm64.sh passes the native package's, same release).
set(NEUFLOW_DEB_SHLIB_DEPENDS "" CACHE STRING
    "The neuflow package's library dependencies, instead of dpkg-shlibdeps' (needed when cross-compiling)")
# What the programs load at run time rather than link: GStreamer's elements (videoconvert,
# the decoders and muxers of base and good) and, recommended, the encoders, the camera source,
# the Vulkan loader and a Vulkan driver.
set(neuflow_runtime_depends "gstreamer1.0-plugins-base, gstreamer1.0-plugins-good")
if(NEUFLOW_DEB_SHLIB_DEPENDS)
  set(CPACK_DEBIAN_RUNTIME_PACKAGE_SHLIBDEPS OFF)
  string(APPEND neuflow_runtime_depends ", ${NEUFLOW_DEB_SHLIB_DEPENDS}")
else()
  set(CPACK_DEBIAN_RUNTIME_PACKAGE_SHLIBDEPS ON)
  # The plugin's metadata library is ours, in the package itself.
  set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS_PRIVATE_DIRS
      "${CMAKE_BINARY_DIR}/plugins")
endif()
set(CPACK_DEBIAN_RUNTIME_PACKAGE_NAME neuflow)
set(CPACK_DEBIAN_RUNTIME_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_RUNTIME_PACKAGE_DEPENDS "${neuflow_runtime_depends}")
set(CPACK_DEBIAN_RUNTIME_PACKAGE_RECOMMENDS
    "gstreamer1.0-plugins-bad, gstreamer1.0-plugins-ugly, gstreamer1.0-libav, libvulkan1, mesa-vulkan-drivers | vulkan-icd")
set(CPACK_DEBIAN_RUNTIME_PACKAGE_SUGGESTS "gstreamer1.0-libcamera, gstreamer1.0-tools")
set(CPACK_COMPONENT_RUNTIME_DESCRIPTION "NeuFlow-V2 optical flow: the neuflow command, the neuflowd daemon and the GStreamer plugin
Learned optical flow for live video and files: neuflow converts image pairs, folders and
videos to flow files and pictures and evaluates them; neuflowd runs capture, flow and sink
graphs from a config file under systemd; the GStreamer elements neuflow, neuflowviz and
neuflowsink do the same in gst-launch pipelines. CPU (oneDNN) and Vulkan backends.")

# Files under /etc are the administrator's once installed: dpkg keeps their edits on upgrade.
file(GLOB neuflow_example_configs RELATIVE ${PROJECT_SOURCE_DIR}/config ${PROJECT_SOURCE_DIR}/config/*.toml)
list(SORT neuflow_example_configs)
list(TRANSFORM neuflow_example_configs PREPEND "/etc/neuflow/examples/")
list(JOIN neuflow_example_configs "\n" neuflow_conffiles)
file(WRITE ${CMAKE_BINARY_DIR}/packaging/conffiles "${neuflow_conffiles}\n")
set(CPACK_DEBIAN_RUNTIME_PACKAGE_CONTROL_EXTRA
    ${CMAKE_BINARY_DIR}/packaging/conffiles
    ${PROJECT_SOURCE_DIR}/packaging/debian/postinst
    ${PROJECT_SOURCE_DIR}/packaging/debian/prerm
    ${PROJECT_SOURCE_DIR}/packaging/debian/postrm)
set(CPACK_DEBIAN_RUNTIME_PACKAGE_CONTROL_STRICT_PERMISSION ON)

set(CPACK_DEBIAN_DEVELOPMENT_PACKAGE_NAME neuflow-dev)
set(CPACK_DEBIAN_DEVELOPMENT_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_DEVELOPMENT_PACKAGE_SECTION libdevel)
# What neuflowConfig.cmake finds again for the static libraries (no installed header includes
# Vulkan or volk: the loader is opened at run time), and flow_meta.h's GStreamer.
set(CPACK_DEBIAN_DEVELOPMENT_PACKAGE_DEPENDS
    "neuflow (= ${neuflow_deb_version}), cmake, pkg-config, libdnnl-dev, libopencv-core-dev, libopencv-imgproc-dev, libopencv-imgcodecs-dev, libopencv-video-dev, libpng-dev, libzip-dev, libgstreamer1.0-dev")
set(CPACK_COMPONENT_DEVELOPMENT_DESCRIPTION "NeuFlow-V2 optical flow: headers, static libraries and CMake package
find_package(neuflow) gives neuflow::model (the network, its sessions, the CPU and Vulkan
backends) and neuflow::flow (flow fields, .flo / KITTI PNG / .npy, colour wheel, metrics).")

# The module is built for one interpreter version (its ABI tag, e.g. cpython-311), which the
# dependency pins; its libraries come from dpkg-shlibdeps as the runtime package's do.
if(NEUFLOW_BUILD_PYTHON AND TARGET neuflow_python)
  string(REPLACE "." ";" neuflow_python_parts "${NEUFLOW_PYTHON_VERSION}")
  list(GET neuflow_python_parts 0 neuflow_python_major)
  list(GET neuflow_python_parts 1 neuflow_python_minor)
  math(EXPR neuflow_python_next "${neuflow_python_minor} + 1")
  set(CPACK_DEBIAN_PYTHON_PACKAGE_NAME python3-neuflow)
  set(CPACK_DEBIAN_PYTHON_FILE_NAME DEB-DEFAULT)
  set(CPACK_DEBIAN_PYTHON_PACKAGE_SECTION python)
  set(CPACK_DEBIAN_PYTHON_PACKAGE_SHLIBDEPS ${CPACK_DEBIAN_RUNTIME_PACKAGE_SHLIBDEPS})
  set(CPACK_DEBIAN_PYTHON_PACKAGE_DEPENDS
      "python3 (>= ${NEUFLOW_PYTHON_VERSION}), python3 (<< ${neuflow_python_major}.${neuflow_python_next}), python3-numpy")
  if(NEUFLOW_DEB_SHLIB_DEPENDS)
    string(APPEND CPACK_DEBIAN_PYTHON_PACKAGE_DEPENDS ", ${NEUFLOW_DEB_SHLIB_DEPENDS}")
  endif()
  set(CPACK_DEBIAN_PYTHON_PACKAGE_CONTROL_EXTRA ${PROJECT_SOURCE_DIR}/packaging/debian/python3-neuflow/prerm)
  set(CPACK_DEBIAN_PYTHON_PACKAGE_CONTROL_STRICT_PERMISSION ON)
  set(CPACK_DEBIAN_PYTHON_PACKAGE_RECOMMENDS "python3-opencv, libvulkan1, mesa-vulkan-drivers | vulkan-icd")
  set(CPACK_COMPONENT_PYTHON_DESCRIPTION "NeuFlow-V2 optical flow for Python: import neuflow
The NeuFlow-V2 core (CPU and Vulkan backends) on NumPy arrays: neuflow.Model and its sessions
compute flow for pairs and streams of frames; read_flow and write_flow take .flo, KITTI PNG and
.npy files; flow_to_color draws the colour wheel; epe and metrics score flow against ground truth.")
endif()

include(CPack)
