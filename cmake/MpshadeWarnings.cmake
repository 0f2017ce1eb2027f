# The instruction-set baseline on x86-64: x86-64-v2 (SSE4.2, 2009 and later) gives the
# rounding instructions hot loops need (floor without a library call). Hot loops that gain
# from AVX2 carry their own AVX2 clone, chosen at run time (target_clones). Empty: the
# compiler's default.
set(MPSHADE_ARCH "x86-64-v2" CACHE STRING "x86-64 baseline for -march (empty: compiler default)")
if(NOT CMAKE_SYSTEM_PROCESSOR MATCHES "^(x86_64|AMD64|amd64)$")
  set(MPSHADE_ARCH "")
endif()

# mpshade_target_defaults(target): warnings (errors with MPSHADE_WERROR), sanitizers with
# MPSHADE_SANITIZE, the instruction-set baseline, and the include root so headers are named
# by module: "geometry/surface.h".
function(mpshade_target_defaults target)
  if(MPSHADE_ARCH)
    target_compile_options(${target} PRIVATE -march=${MPSHADE_ARCH})
  endif()
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wno-unused-parameter)
  if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
    # GCC 12 reports false -Wrestrict positives inside std::string at -O3 (GCC bug 105329).
    target_compile_options(${target} PRIVATE -Wshadow=local -Wno-restrict)
  endif()
  if(MPSHADE_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
  if(MPSHADE_FUZZ)
    # Coverage instrumentation for libFuzzer in every library the targets link.
    target_compile_options(${target} PUBLIC -fsanitize=fuzzer-no-link)
  endif()
  if(MPSHADE_SANITIZE)
    target_compile_options(${target} PUBLIC -fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer)
    target_link_options(${target} PUBLIC -fsanitize=address,undefined)
  endif()
endfunction()

# mpshade_library(name SOURCES ... DEPS ...): one library per module folder.
function(mpshade_library name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS" ${ARGN})
  add_library(${name} STATIC ${ARG_SOURCES})
  target_link_libraries(${name} PUBLIC ${ARG_DEPS})
  mpshade_target_defaults(${name})
  mpshade_install_library(${name})
endfunction()

# mpshade_install_library(name): the include root (the source tree when built, include/mpshade
# when installed, so headers are named "geometry/surface.h" either way), and the library and
# its folder's headers installed as mpshade::<folder> in the exported package
# (cmake/mpshadeConfig.cmake.in).
function(mpshade_install_library name)
  get_filename_component(folder ${CMAKE_CURRENT_SOURCE_DIR} NAME)
  target_include_directories(${name} PUBLIC
    $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}>
    $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}/mpshade>)
  set_target_properties(${name} PROPERTIES EXPORT_NAME ${folder})
  install(TARGETS ${name} EXPORT mpshadeTargets ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
  install(DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR}/
          DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/mpshade/${folder}
          FILES_MATCHING PATTERN "*.h")
endfunction()
