// PCD files read as the format's reference implementation reads them: every PCD the shared
// datasets hold (ACFR's VLP-16 scans and board segments, OpenCalib's Pandar64 road frames as
// published, one with 3,870 bytes after its binary_compressed block) read by our loader and by
// PCL's pcl::io::loadPCDFile give the same points in the same order, bit for bit (our loader
// drops the non-finite ones).
#include <gtest/gtest.h>
#include <pcl/PCLPointCloud2.h>
#include <pcl/conversions.h>
#include <pcl/io/pcd_io.h>
#include <pcl/point_types.h>

#include <cmath>
#include <filesystem>
#include <vector>

#include "core/base/notice.h"
#include "core/io/cloud_io.h"
#include "tests/test_support.h"

namespace calibench {
namespace {

namespace fs = std::filesystem;

TEST(PcdAsPcl, EverySharedPcdReadsAsPclReadsIt) {
  CALIBENCH_REQUIRE_SHARED_DIR(shared);
  int files = 0;
  bool saw_trailing_bytes = false;
  for (const auto& entry : fs::recursive_directory_iterator(shared / "datasets")) {
    if (entry.path().extension() != ".pcd") continue;
    SCOPED_TRACE(entry.path().string());
    pcl::PCLPointCloud2 blob;
    ASSERT_EQ(pcl::io::loadPCDFile(entry.path().string(), blob), 0);
    pcl::PointCloud<pcl::PointXYZ> by_pcl;
    pcl::fromPCLPointCloud2(blob, by_pcl);
    std::vector<Eigen::Vector3f> finite;
    for (const pcl::PointXYZ& p : by_pcl.points)
      if (std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z))
        finite.emplace_back(p.x, p.y, p.z);
    const int noted = NotedCount("pcd-trailing-data");
    const LidarCloud ours = LoadCloud(entry.path());
    saw_trailing_bytes |= NotedCount("pcd-trailing-data") > noted;
    ASSERT_EQ(ours.size(), finite.size());
    for (size_t i = 0; i < finite.size(); ++i)
      ASSERT_EQ(ours.points[i], finite[i]) << "point " << i;
    ++files;
  }
  EXPECT_GE(files, 80);  // ACFR's 80 scans and segments, the road frames
  EXPECT_TRUE(saw_trailing_bytes) << "rig-b/clouds/scene3.pcd carries bytes after its data";
}

}  // namespace
}  // namespace calibench
