# Third-party dependencies, all from Debian 12 packages (see scripts/setup.sh and docs/building.md).
find_package(glm CONFIG REQUIRED)
find_package(TBB CONFIG REQUIRED)
find_package(embree 3 CONFIG REQUIRED)
find_package(nlohmann_json CONFIG REQUIRED)
find_package(fmt CONFIG REQUIRED)
find_package(CLI11 CONFIG REQUIRED)
find_package(OpenImageIO CONFIG REQUIRED)
find_package(OpenEXR CONFIG REQUIRED)
find_package(PNG REQUIRED)

include(MpshadeImportedLibraries)

if(MPSHADE_BUILD_TESTS)
  find_package(GTest CONFIG REQUIRED)
endif()
if(MPSHADE_BUILD_BENCH)
  find_package(benchmark CONFIG REQUIRED)
endif()
