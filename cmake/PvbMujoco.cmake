# Debian's MuJoCo 2.2.2 package exports an imported target whose interface
# include directories name /usr/include/libqhull_r.  That folder only exists
# when libqhull-dev is installed, and CMake rejects imported targets with
# missing include folders.  ci/install-deps.sh installs libqhull-dev; this
# module additionally drops any listed include folder that does not exist, so a
# machine without it still configures (MuJoCo's public headers never include
# qhull).
find_package(mujoco 2.2 REQUIRED)
if(TARGET mujoco::mujoco)
  get_target_property(_pvb_mj_inc mujoco::mujoco INTERFACE_INCLUDE_DIRECTORIES)
  set(_pvb_mj_kept "")
  foreach(_dir IN LISTS _pvb_mj_inc)
    if(EXISTS "${_dir}")
      list(APPEND _pvb_mj_kept "${_dir}")
    else()
      message(STATUS "MuJoCo: dropping missing include folder ${_dir}")
    endif()
  endforeach()
  set_target_properties(mujoco::mujoco PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${_pvb_mj_kept}")
endif()
