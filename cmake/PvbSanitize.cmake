# Sanitizer and fuzzing builds (docs/testing.md).
#
#   PVB_SANITIZE=address,undefined   ASan + UBSan (ci/sanitize.sh)
#   PVB_SANITIZE=thread              TSan (threaded runs; docs/testing.md)
#   PVB_FUZZ=ON                      libFuzzer targets in tests/fuzz (clang only;
#                                    ci/fuzz.sh), with ASan + UBSan
#
# The flags go on every target of the build, so the libraries the tests and
# pvbench link are instrumented too.  Third-party libraries (OpenCV, Ceres,
# MuJoCo, Mesa, OpenNI2) are not: their reports are suppressed with a reason
# in ci/sanitizers/.
set(PVB_SANITIZE "" CACHE STRING "Sanitizers to build with: address,undefined or thread (empty: none)")
option(PVB_FUZZ "Build the libFuzzer targets (clang; implies address,undefined)" OFF)

if(PVB_FUZZ)
  if(NOT CMAKE_CXX_COMPILER_ID MATCHES "Clang")
    message(FATAL_ERROR "PVB_FUZZ needs clang (libFuzzer): configure with CC=clang CXX=clang++")
  endif()
  if(PVB_SANITIZE STREQUAL "")
    set(PVB_SANITIZE "address,undefined")
  endif()
endif()

if(NOT PVB_SANITIZE STREQUAL "")
  if(PVB_SANITIZE MATCHES "thread" AND PVB_SANITIZE MATCHES "address")
    message(FATAL_ERROR "PVB_SANITIZE: thread cannot be combined with address")
  endif()
  # Frame pointers for whole stacks; undefined behaviour stops the program
  # (so a test fails) instead of printing and going on.  -fno-sanitize=vptr:
  # the vptr check needs RTTI of every class it meets, and the uninstrumented
  # OpenCV and Ceres types it would meet give false reports.
  set(_pvb_san "-fsanitize=${PVB_SANITIZE}" -fno-omit-frame-pointer)
  if(PVB_SANITIZE MATCHES "undefined")
    list(APPEND _pvb_san -fno-sanitize-recover=undefined -fno-sanitize=vptr)
  endif()
  add_compile_options(${_pvb_san})
  add_link_options(${_pvb_san})
  message(STATUS "Sanitizers: ${PVB_SANITIZE}")
endif()

if(PVB_FUZZ)
  # Coverage for libFuzzer in every library; the fuzz targets link the
  # fuzzer's main() themselves (-fsanitize=fuzzer, tests/fuzz).
  add_compile_options(-fsanitize=fuzzer-no-link)
endif()

# Plug-in modules are linked with --no-undefined (every symbol they need
# resolved at link time), but for clang's sanitizers: clang puts the
# sanitizer runtime into the executable only, and a module loaded into an
# instrumented pvbench finds its __asan_* symbols there.
set(PVB_MODULE_NO_UNDEFINED -Wl,--no-undefined)
if(NOT PVB_SANITIZE STREQUAL "" AND CMAKE_CXX_COMPILER_ID MATCHES "Clang")
  set(PVB_MODULE_NO_UNDEFINED)
endif()
