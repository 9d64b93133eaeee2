# Included once Fast DDS 2 (`fastrtps`) is found: by the top level, and by the installed rsgConfig.cmake
# (find_package(rsg) in a consumer, beside which it is installed).
#
# ROS 2 Jazzy's PyPI wheel of Fast DDS 2.14 (ros-fastrtps) exports a fastrtps target that names
# its build machine's TinyXML-2 (/usr/lib64/libtinyxml2.so), a file no other machine has, while its
# libfastrtps.so loads the copy the wheel carries (ros_fastrtps.libs/libtinyxml2-<hash>.so.6). The
# missing file stops every link ("No rule to make target"), and the system's TinyXML-2 beside the
# wheel's would put two ABIs of one unversioned library in the process, Fast DDS's XML parser
# binding to whichever came first. So the target gets the wheel's copy instead, and
# RSG_FASTRTPS_TINYXML2 names it for rsg_dds (src/dds/CMakeLists.txt): one TinyXML-2 per process,
# the one Fast DDS was built with. A Fast DDS whose TinyXML-2 exists (Debian's, an apt-installed
# ROS 2) is left as it is.
get_target_property(_rsg_fastrtps_libs fastrtps INTERFACE_LINK_LIBRARIES)
set(_rsg_fastrtps_fixed)
foreach(_rsg_lib IN LISTS _rsg_fastrtps_libs)
  if(_rsg_lib MATCHES "tinyxml2" AND IS_ABSOLUTE "${_rsg_lib}" AND NOT EXISTS "${_rsg_lib}")
    get_target_property(_rsg_fastrtps_so fastrtps IMPORTED_LOCATION_RELEASE)
    get_filename_component(_rsg_fastrtps_dir "${_rsg_fastrtps_so}" DIRECTORY)
    file(GLOB _rsg_bundled "${_rsg_fastrtps_dir}/python3*/site-packages/ros_fastrtps.libs/libtinyxml2*.so*")
    if(NOT _rsg_bundled)
      message(FATAL_ERROR "Fast DDS (${_rsg_fastrtps_so}) links ${_rsg_lib}, which does not exist, and no "
                          "TinyXML-2 of its own was found next to it (ros_fastrtps.libs)")
    endif()
    list(GET _rsg_bundled 0 _rsg_bundled)
    set(RSG_FASTRTPS_TINYXML2 ${_rsg_bundled})
    message(STATUS "rsg: Fast DDS's own TinyXML-2 ${RSG_FASTRTPS_TINYXML2} (its target named ${_rsg_lib})")
    set(_rsg_lib ${_rsg_bundled})
  endif()
  list(APPEND _rsg_fastrtps_fixed "${_rsg_lib}")
endforeach()
if(RSG_FASTRTPS_TINYXML2)
  set_target_properties(fastrtps PROPERTIES INTERFACE_LINK_LIBRARIES "${_rsg_fastrtps_fixed}")
  # The wheel's libfastrtps.so finds the libraries it carries (OpenSSL 1.1.1k, TinyXML-2) through an
  # RPATH that points nowhere once pip has installed it (lib/ is not beside ros_fastrtps.libs/): a
  # sourced ROS 2 environment's LD_LIBRARY_PATH names them. rsg's programs carry the directory as
  # RPATH, not RUNPATH, which the loader also applies to their libraries' own dependencies, so they
  # run without that environment too.
  get_filename_component(_rsg_bundled_dir "${RSG_FASTRTPS_TINYXML2}" DIRECTORY)
  set_property(TARGET fastrtps APPEND PROPERTY INTERFACE_LINK_OPTIONS
               "LINKER:--disable-new-dtags" "LINKER:-rpath,${_rsg_bundled_dir}")
endif()
