# Libraries whose Debian packages ship no usable CMake config, imported by hand; and
# OpenImageIO's include directories mended. Included by the build and by the installed
# package's config (mpshadeConfig.cmake), so a consumer sees the same targets.

# OpenImageIO's exported target names /usr/include/opencv4, which exists only when
# libopencv-core-dev is installed; drop include directories that do not exist.
if(TARGET OpenImageIO::OpenImageIO)
  get_target_property(_oiio_inc OpenImageIO::OpenImageIO INTERFACE_INCLUDE_DIRECTORIES)
endif()
if(_oiio_inc)
  set(_oiio_kept "")
  foreach(_dir IN LISTS _oiio_inc)
    if(_dir MATCHES "^\\$<" OR EXISTS "${_dir}")
      list(APPEND _oiio_kept "${_dir}")
    endif()
  endforeach()
  set_target_properties(OpenImageIO::OpenImageIO PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${_oiio_kept}")
endif()

# mpshade_import(TARGET HEADER LIBRARY): a library found by one of its headers and its
# name, as the UNKNOWN IMPORTED target TARGET (kept if it exists: the config may be read
# twice).
function(mpshade_import target header library)
  string(MAKE_C_IDENTIFIER "${target}" id)
  find_path(${id}_INCLUDE_DIR ${header} REQUIRED)
  find_library(${id}_LIBRARY ${library} REQUIRED)
  if(NOT TARGET ${target})
    add_library(${target} UNKNOWN IMPORTED)
    set_target_properties(${target} PROPERTIES
      IMPORTED_LOCATION "${${id}_LIBRARY}"
      INTERFACE_INCLUDE_DIRECTORIES "${${id}_INCLUDE_DIR}")
  endif()
endfunction()

# OpenSubdiv's Debian CMake config names static libraries the package does not ship, so it
# is found by hand. libosdCPU holds Far, Sdc, Vtr and Bfr.
mpshade_import(mpshade::opensubdiv opensubdiv/version.h osdCPU)

# xxHash (libxxhash-dev) has no CMake config either: XXH3 digests address the shader-map
# store (shadermaps/tile_store.h) and check its tiles.
mpshade_import(mpshade::xxhash xxhash.h xxhash)
