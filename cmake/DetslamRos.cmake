# detslam_find_ros(PREFIX HEADERS header... LIBRARIES lib...)
# Looks up Debian's ROS 1 headers and libraries directly (Debian's catkin CMake configs need
# ament's Python tools). Sets PREFIX_INCLUDE_DIRS, PREFIX_LIBRARIES and PREFIX_MISSING (what was
# not found; empty when everything was) in the caller's scope.
function(detslam_find_ros prefix)
  cmake_parse_arguments(ARG "" "" "HEADERS;LIBRARIES" ${ARGN})
  set(include_dirs "")
  set(libraries "")
  set(missing "")
  foreach(header ${ARG_HEADERS})
    string(REGEX REPLACE "/.*" "" pkg "${header}")
    string(MAKE_C_IDENTIFIER "DETSLAM_ROS_INC_${header}" var)
    # Some packages (pluginlib, class_loader, rcutils, ...) nest their headers one folder deeper.
    find_path(${var} ${header} PATHS /usr/include PATH_SUFFIXES ${pkg} NO_DEFAULT_PATH)
    if(${var})
      list(APPEND include_dirs ${${var}})
    else()
      list(APPEND missing ${header})
    endif()
  endforeach()
  foreach(lib ${ARG_LIBRARIES})
    string(MAKE_C_IDENTIFIER "DETSLAM_ROS_LIB_${lib}" var)
    find_library(${var} ${lib})
    if(${var})
      list(APPEND libraries ${${var}})
    else()
      list(APPEND missing lib${lib})
    endif()
  endforeach()
  list(REMOVE_DUPLICATES include_dirs)
  set(${prefix}_INCLUDE_DIRS "${include_dirs}" PARENT_SCOPE)
  set(${prefix}_LIBRARIES "${libraries}" PARENT_SCOPE)
  set(${prefix}_MISSING "${missing}" PARENT_SCOPE)
endfunction()

# detslam_ros_missing(WHAT MISSING PACKAGES): in CI (CI=true) a fatal error, elsewhere a note that
# WHAT is left out, naming the Debian PACKAGES to install.
function(detslam_ros_missing what missing packages)
  if("$ENV{CI}" STREQUAL "true")
    message(FATAL_ERROR "CI: ${what} needs ROS 1 packages; missing: ${missing} "
                        "(apt-get install ${packages})")
  endif()
  message(STATUS "${what} left out (missing: ${missing}); apt-get install ${packages} to build it")
endfunction()

# What writing bags with ROS's rosbag C++ API needs (tests only).
set(DETSLAM_ROSBAG_API_HEADERS rosbag/bag.h sensor_msgs/Image.h tf2_msgs/TFMessage.h
    pluginlib/class_loader.hpp class_loader/class_loader.hpp rcutils/types.h
    rcpputils/filesystem_helper.hpp ament_index_cpp/get_resource.hpp)
set(DETSLAM_ROSBAG_API_LIBRARIES rosbag_storage roscpp_serialization rostime cpp_common
    console_bridge class_loader boost_filesystem)
