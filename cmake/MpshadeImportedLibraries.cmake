# Libraries whose Debian packages ship no usable CMake config, imported by hand; and
# OpenImageIO's include directories mended. Included by the build and by the installed
# package's config (mpshadeConfig.cmake), so a consumer sees the same targets.

# OpenImageIO's exported target names /usr/include/opencv4, which exists only when
# libopencv-core-dev is installed; drop include directories that do not exist.
get_target_property(_oiio_inc OpenImageIO::OpenImageIO INTERFACE_INCLUDE_DIRECTORIES)
if(_oiio_inc)
  set(_oiio_kept "")
  foreach(_dir IN LISTS _oiio_inc)
    if(_dir MATCHES "^\\$<" OR EXISTS "${_dir}")
      list(APPEND _oiio_kept "${_dir}")
    endif()
  endforeach()
  set_target_properties(OpenImageIO::OpenImageIO PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${_oiio_kept}")
endif()

# OpenSubdiv's Debian CMake config names static libraries the package does not ship, so it
# is found by hand. libosdCPU holds Far, Sdc, Vtr and Bfr.
find_path(OPENSUBDIV_INCLUDE_DIR opensubdiv/version.h REQUIRED)
find_library(OPENSUBDIV_CPU_LIBRARY osdCPU REQUIRED)
if(NOT TARGET mpshade::opensubdiv)
  add_library(mpshade::opensubdiv UNKNOWN IMPORTED)
  set_target_properties(mpshade::opensubdiv PROPERTIES
    IMPORTED_LOCATION "${OPENSUBDIV_CPU_LIBRARY}"
    INTERFACE_INCLUDE_DIRECTORIES "${OPENSUBDIV_INCLUDE_DIR}")
endif()

# xxHash (libxxhash-dev) has no CMake config either: XXH3 digests address the shader-map
# store (shadermaps/tile_store.h) and check its tiles.
find_path(XXHASH_INCLUDE_DIR xxhash.h REQUIRED)
find_library(XXHASH_LIBRARY xxhash REQUIRED)
if(NOT TARGET mpshade::xxhash)
  add_library(mpshade::xxhash UNKNOWN IMPORTED)
  set_target_properties(mpshade::xxhash PROPERTIES
    IMPORTED_LOCATION "${XXHASH_LIBRARY}"
    INTERFACE_INCLUDE_DIRECTORIES "${XXHASH_INCLUDE_DIR}")
endif()

