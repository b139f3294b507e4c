// A simulated capture recorded as a ROS recording, as a user makes one on-site: the board held
// still at each pose for `hold_s`, carried to the next over `move_s`, a spinning LiDAR and a
// camera streaming throughout (PointCloud2, Image, CameraInfo). What import and watch must sort
// into one pair per hold.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "core/base/types.h"
#include "core/camera/camera.h"
#include "core/recording/bag.h"
#include "core/sim/sim.h"
#include "core/sim/sim_wave.h"
#include "tests/bag_writers.h"

namespace calibench::test {

struct SimRecordingOptions {
  int poses = 30;
  double hold_s = 6.0;
  double move_s = 2.0;
  double cloud_hz = 10.0;
  double image_hz = 15.0;
  int image_width = 1280, image_height = 720;
  BoardSpec board;                                    // cols == 0: the A3 preset
  double lidar_range_noise_m = 0.01;                  // a VLP-16's
  double min_distance_m = 1.5, max_distance_m = 4.0;  // board centre from the camera
  std::uint64_t seed = 7;
  // A rig: a second camera like the first, turned this far to the left about the LiDAR's z axis
  // (degrees) and 20 cm to the left; the topics are then /cam0/... and /cam1/... (0 = one
  // camera on /camera/...).
  double second_camera_yaw_deg = 0.0;
  // The LiDAR: a spinning one (PointCloud2 on /velodyne_points), or a Livox-class scanner
  // (mid40, avia, mid360), whose 0.1 s frames go out as livox_ros_driver/CustomMsg (ROS 1) or
  // livox_ros_driver2/CustomMsg (ROS 2) on /livox/lidar, each frame a new stretch of its
  // rosette.
  LidarModel lidar = LidarModel::kVlp16;
  // A spinning LiDAR's returns with their own times, as velodyne_pointcloud's XYZIRT gives them:
  // a float32 field `time`, seconds after the sweep's stamp (its start), from each return's
  // azimuth after the sweep's firing phase.
  bool point_times = false;
  // The camera's stamps off the LiDAR's clock (seconds; +0.080: 80 ms late), as a USB camera's.
  double camera_minus_lidar_s = 0.0;
};

struct SimRecordingTruth {
  std::vector<Pose> held_cam_from_board;  // per pose
  std::vector<std::int64_t> hold_start_ns, hold_end_ns;
  CameraModel camera;
  BoardSpec board;
  Pose cam_from_lidar;
  std::optional<Pose> second_cam_from_lidar;  // the rig's second camera (same model)
  double seconds = 0.0;                       // the recording's length
  std::int64_t messages = 0;
};

// Hands messages on to `inner`, calling `pause` once before the first message stamped at or after
// `at_ns`: a recorder held mid-recording while a test waits for what a follower says.
class PausingWriter : public RecordingWriter {
 public:
  PausingWriter(std::unique_ptr<RecordingWriter> inner, std::function<void()> pause,
                std::int64_t at_ns)
      : inner_(std::move(inner)), pause_(std::move(pause)), at_ns_(at_ns) {}
  void Add(const RecordedMessage& message) override {
    if (pause_ && message.log_time_ns >= at_ns_) std::exchange(pause_, nullptr)();
    inner_->Add(message);
  }
  void Close() override { inner_->Close(); }

 private:
  std::unique_ptr<RecordingWriter> inner_;
  std::function<void()> pause_;
  std::int64_t at_ns_;
};

// What the tests record: 4 s of sensors per pose instead of 8, 640 x 360 images with the board
// within 2.5 m (40 mm squares stay >= 7 px).
SimRecordingOptions SmallSimRecording(int poses);

// The recording's truth without writing it (the held poses, spans, camera, board, mount).
SimRecordingTruth PlanSimRecording(const SimRecordingOptions& options);

// Writes the recording through `writer` (not closed) in log-time order; `encoding` is the
// writer's (ROS 1 for .bag, CDR for ROS 2 MCAP).
SimRecordingTruth WriteSimRecording(RecordingWriter* writer, MessageEncoding encoding,
                                    const SimRecordingOptions& options);

// A waved board's recording (core/sim/sim_wave.h, simulated under `scratch` with every sweep
// written): each sweep a PointCloud2 stamped at its start on the LiDAR's clock and logged once
// complete, on /velodyne_points with velodyne's per-point `time` (float32 s), or with
// PointLayout::kOuster on /os_cloud_node/points with Ouster's `t` (uint32 ns), or for a
// Livox-class LiDAR a CustomMsg on /livox/lidar with its points' offset_time; each frame an
// Image on /camera/image_raw stamped on the camera's clock (wave.camera_minus_lidar_s off), with
// its CameraInfo. Written through `writer` (not closed) in log-time order.
WavedDataset WriteWavedRecording(RecordingWriter* writer, MessageEncoding encoding,
                                 WaveOptions wave, const std::filesystem::path& scratch,
                                 PointLayout layout = PointLayout::kVelodyne);

}  // namespace calibench::test
