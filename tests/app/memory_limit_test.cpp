// The memory default under a container: the smallest limit of the process's cgroup and the
// groups above it, in cgroup v2 and v1 layouts, read from files made here.
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "app/memory_limit.h"

namespace mpshade {
namespace {

namespace fs = std::filesystem;

fs::path fresh(const std::string& name) {
    const fs::path dir = fs::path(::testing::TempDir()) / ("mpshade_cgroup_" + name);
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

void put(const fs::path& file, const std::string& text) {
    fs::create_directories(file.parent_path());
    std::ofstream(file) << text;
}

TEST(MemoryLimit, CgroupV2TakesTheSmallestLimitUpTheHierarchy) {
    const fs::path dir = fresh("v2");
    put(dir / "cgroup", "0::/farm/job7\n");
    put(dir / "root/farm/job7/memory.max", "max\n");
    put(dir / "root/farm/memory.max", "4294967296\n");
    EXPECT_EQ(cgroupLimitFrom((dir / "cgroup").string(), (dir / "root").string()),
              uint64_t{4294967296});
    put(dir / "root/farm/job7/memory.max", "1073741824\n");
    EXPECT_EQ(cgroupLimitFrom((dir / "cgroup").string(), (dir / "root").string()),
              uint64_t{1073741824});
}

TEST(MemoryLimit, CgroupV1ReadsTheMemoryControllerAndIgnoresItsNoLimitValue) {
    const fs::path dir = fresh("v1");
    put(dir / "cgroup", "5:cpu:/a\n4:memory:/job\n");
    put(dir / "root/memory/job/memory.limit_in_bytes", "9223372036854771712\n");  // no limit
    EXPECT_EQ(cgroupLimitFrom((dir / "cgroup").string(), (dir / "root").string()), 0u);
    put(dir / "root/memory/job/memory.limit_in_bytes", "2147483648\n");
    EXPECT_EQ(cgroupLimitFrom((dir / "cgroup").string(), (dir / "root").string()),
              uint64_t{2147483648});
}

TEST(MemoryLimit, NoCgroupFileMeansNoLimit) {
    EXPECT_EQ(cgroupLimitFrom("/nonexistent/cgroup", "/nonexistent"), 0u);
}

}  // namespace
}  // namespace mpshade
