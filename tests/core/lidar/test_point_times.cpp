// Each return's own time read as the drivers write it (core/lidar/point_times.h): the unit and
// the origin told from the field's type and the values' spread.
#include <gtest/gtest.h>

#include <cmath>

#include "core/lidar/point_times.h"

namespace calibench {
namespace {

constexpr double kLuminarStampS =
    1604515190.231;  // a real recording's stamp (ros1_luminar_lidar_lz4)

// n values from `first` to `last`, evenly.
std::vector<double> TimesFromTo(double first, double last, int n = 1000) {
  std::vector<double> values;
  for (int i = 0; i < n; ++i) values.push_back(first + (last - first) * i / (n - 1));
  return values;
}

TEST(PointTimes, VelodynesFloatSecondsBeforeTheStampAreReadAsThey) {
  // velodyne_pointcloud's `time`: float32 s relative to header.stamp, negative when the driver
  // stamps the sweep's last packet.
  const std::vector<double> raw = TimesFromTo(-0.0995, 0.0);
  const PointTimeReading r = ReadPointTimes({"time", false, "FLOAT32"}, raw, kLuminarStampS);
  ASSERT_TRUE(r.ok) << r.words;
  EXPECT_FALSE(r.on_the_clock);
  EXPECT_DOUBLE_EQ(r.seconds_per_unit, 1.0);
  EXPECT_NEAR(r.first_s, -0.0995, 1e-12);
  EXPECT_NEAR(r.last_s, 0.0, 1e-12);
  EXPECT_NE(r.words.find("'time' (FLOAT32), read as seconds after the stamp"), std::string::npos)
      << r.words;
  const std::vector<float> t = PointTimesAfterStamp(raw, r, kLuminarStampS);
  ASSERT_EQ(t.size(), raw.size());
  EXPECT_NEAR(t.front(), -0.0995, 1e-7);
}

TEST(PointTimes, OustersIntegerNanosecondsAfterTheStamp) {
  const std::vector<double> raw = TimesFromTo(0, 99'951'171);  // 2047/2048 of a 10 Hz sweep
  const PointTimeReading r = ReadPointTimes({"t", true, "UINT32"}, raw, kLuminarStampS);
  ASSERT_TRUE(r.ok) << r.words;
  EXPECT_FALSE(r.on_the_clock);
  EXPECT_DOUBLE_EQ(r.seconds_per_unit, 1e-9);
  EXPECT_NEAR(r.last_s, 0.099951171, 1e-9);
  EXPECT_NE(r.words.find("nanoseconds after the stamp"), std::string::npos) << r.words;
}

TEST(PointTimes, HesaisFloatSecondsOnTheClockBecomeTimesAfterTheStamp) {
  // Hesai / Robosense `timestamp`: float64 s on the LiDAR's clock, the sweep's first at the stamp.
  const std::vector<double> raw = TimesFromTo(kLuminarStampS, kLuminarStampS + 0.1);
  const PointTimeReading r = ReadPointTimes({"timestamp", false, "FLOAT64"}, raw, kLuminarStampS);
  ASSERT_TRUE(r.ok) << r.words;
  EXPECT_TRUE(r.on_the_clock);
  EXPECT_DOUBLE_EQ(r.seconds_per_unit, 1.0);
  const std::vector<float> t = PointTimesAfterStamp(raw, r, kLuminarStampS);
  EXPECT_NEAR(t.front(), 0.0, 1e-6);  // a float64 second on the clock keeps its microseconds
  EXPECT_NEAR(t.back(), 0.1, 1e-6);
  EXPECT_NEAR(t[500], 0.1 * 500 / 999, 1e-6);
}

TEST(PointTimes, LivoxDriver2sFloatNanosecondsOnTheClock) {
  const std::vector<double> raw =
      TimesFromTo((kLuminarStampS + 0.002) * 1e9, (kLuminarStampS + 0.102) * 1e9);
  const PointTimeReading r = ReadPointTimes({"timestamp", false, "FLOAT64"}, raw, kLuminarStampS);
  ASSERT_TRUE(r.ok) << r.words;
  EXPECT_TRUE(r.on_the_clock);
  EXPECT_DOUBLE_EQ(r.seconds_per_unit, 1e-9);
  EXPECT_NEAR(r.first_s, 0.002, 1e-6);
  EXPECT_NEAR(r.last_s, 0.102, 1e-6);
  EXPECT_NE(r.words.find("nanoseconds on the LiDAR's clock"), std::string::npos) << r.words;
}

TEST(PointTimes, ValuesNoUnitExplainsAreRefusedWithTheirReason) {
  // Seconds on the clock without a clock to read them against (a file's field): not after the
  // stamp either, so not read — and said, never silently zero.
  const PointTimeReading file = ReadPointTimes(
      {"t", false, "F4"}, TimesFromTo(kLuminarStampS, kLuminarStampS + 0.1), std::nullopt);
  EXPECT_FALSE(file.ok);
  EXPECT_NE(file.words.find("treated as instantaneous"), std::string::npos) << file.words;
  EXPECT_TRUE(
      PointTimesAfterStamp(TimesFromTo(kLuminarStampS, kLuminarStampS + 0.1), file, std::nullopt)
          .empty());
  // A day away from the stamp in every unit.
  EXPECT_FALSE(ReadPointTimes({"timestamp", false, "FLOAT64"},
                              TimesFromTo(kLuminarStampS + 86400, kLuminarStampS + 86400.1),
                              kLuminarStampS)
                   .ok);
  // A value that is not finite.
  std::vector<double> broken = TimesFromTo(0, 0.1);
  broken[7] = std::nan("");
  const PointTimeReading nan = ReadPointTimes({"time", false, "FLOAT32"}, broken, kLuminarStampS);
  EXPECT_FALSE(nan.ok);
  EXPECT_NE(nan.words.find("not finite"), std::string::npos) << nan.words;
}

TEST(PointTimes, ALineScannersLongSweepStaysWithinTheSpanItIsAllowed) {
  // A line scanner on a rotary stage: a 12 s sweep, seconds after the stamp.
  EXPECT_TRUE(ReadPointTimes({"t", false, "F4"}, TimesFromTo(0, 12.0), std::nullopt).ok);
  PointTimeOptions tight;
  tight.max_span_s = 5.0;
  EXPECT_FALSE(ReadPointTimes({"t", false, "F4"}, TimesFromTo(0, 12.0), std::nullopt, tight).ok);
  std::string why;
  tight.max_span_s = 0.0;
  EXPECT_FALSE(tight.Check(&why));
  EXPECT_FALSE(why.empty());
}

TEST(PointTimes, ACloudsTimesInWords) {
  EXPECT_EQ(DescribePointTimes({}), "no per-point times: treated as instantaneous");
  EXPECT_EQ(DescribePointTimes({-0.05f, 0.0f, 0.0495f}),
            "the returns span 99.5 ms (-0.0500 .. 0.0495 s after the stamp)");
}

}  // namespace
}  // namespace calibench
