# Shared by the three message packages of easynav-interfaces.
#
# The ROS 2 wheels on PyPI export CMake targets whose INTERFACE_INCLUDE_DIRECTORIES
# still name include directories of the machine that built them (for example
# /opt/python/cp311-cp311/include/python3.11 on the *__rosidl_generator_py targets).
# CMake refuses to use an imported target that names a directory that does not
# exist, so a build against the wheels fails unless those entries are removed.
#
# Call easynav_strip_foreign_include_dirs() after rosidl_generate_interfaces():
# every imported target of the calling directory loses the include directories
# that start with one of the given prefixes (default: /opt/python/). With a
# regular ROS 2 installation no target names such a directory, and the call
# changes nothing.

function(easynav_strip_foreign_include_dirs)
  set(_prefixes ${ARGN})
  if(NOT _prefixes)
    set(_prefixes "/opt/python/")
  endif()
  get_directory_property(_targets IMPORTED_TARGETS)
  set(_stripped 0)
  foreach(_target IN LISTS _targets)
    get_target_property(_dirs ${_target} INTERFACE_INCLUDE_DIRECTORIES)
    if(NOT _dirs)
      continue()
    endif()
    set(_kept "")
    set(_changed FALSE)
    foreach(_dir IN LISTS _dirs)
      set(_foreign FALSE)
      foreach(_prefix IN LISTS _prefixes)
        string(FIND "${_dir}" "${_prefix}" _pos)
        if(_pos EQUAL 0)
          set(_foreign TRUE)
        endif()
      endforeach()
      if(_foreign)
        set(_changed TRUE)
      else()
        list(APPEND _kept "${_dir}")
      endif()
    endforeach()
    if(_changed)
      set_property(TARGET ${_target} PROPERTY INTERFACE_INCLUDE_DIRECTORIES "${_kept}")
      math(EXPR _stripped "${_stripped} + 1")
    endif()
  endforeach()
  if(_stripped GREATER 0)
    message(STATUS "easynav: removed foreign include directories from ${_stripped} imported targets")
  endif()
endfunction()
