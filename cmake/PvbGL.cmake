# Off-screen GL for MuJoCo.  Each backend is its own MODULE library that the
# simulator dlopen()s at run time, so a process only ever loads one of libEGL
# and libOSMesa (MuJoCo 2.2.2 fails to load GL when both are present).
pkg_check_modules(PVB_EGL IMPORTED_TARGET egl)
pkg_check_modules(PVB_OSMESA IMPORTED_TARGET osmesa)
if(NOT PVB_EGL_FOUND AND NOT PVB_OSMESA_FOUND)
  message(FATAL_ERROR "Neither EGL (libegl-dev) nor OSMesa (libosmesa6-dev) was found: "
                      "no off-screen rendering backend can be built.")
endif()
