#include "tests/sim_recording.h"

#include <algorithm>
#include <cmath>
#include <random>

#include "core/io/cloud_io.h"
#include "core/io/image_io.h"

namespace calibench::test {

namespace {

constexpr std::int64_t kSecond = 1'000'000'000;
constexpr std::int64_t kStart = 1'700'000'000 * kSecond;  // a plausible epoch stamp

// The board pose at time t: held, or on its way between two held poses (linear in position,
// spherical in rotation, eased so that it starts and stops smoothly).
Pose BoardAt(const SimRecordingTruth& truth, std::int64_t t) {
  const auto& poses = truth.held_cam_from_board;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    if (t < truth.hold_start_ns[i]) {
      const std::int64_t from = truth.hold_end_ns[i - 1], to = truth.hold_start_ns[i];
      const double s = static_cast<double>(t - from) / static_cast<double>(to - from);
      const double eased = 0.5 - 0.5 * std::cos(M_PI * s);
      const Eigen::Quaterniond a(poses[i - 1].rotation()), b(poses[i].rotation());
      Pose pose = Pose::Identity();
      pose.linear() = a.slerp(eased, b).toRotationMatrix();
      pose.translation() =
          (1 - eased) * poses[i - 1].translation() + eased * poses[i].translation();
      return pose;
    }
    if (t < truth.hold_end_ns[i]) return poses[i];
  }
  return poses.back();
}

bool Held(const SimRecordingTruth& truth, std::int64_t t, int* pose) {
  for (std::size_t i = 0; i < truth.hold_start_ns.size(); ++i)
    if (t >= truth.hold_start_ns[i] && t < truth.hold_end_ns[i]) {
      *pose = static_cast<int>(i);
      return true;
    }
  return false;
}

// Sensor noise on a rendered image, so that the frames of a hold are not byte-identical.
ImageU8 WithNoise(const ImageU8& image, std::mt19937_64* rng) {
  ImageU8 noisy = image;
  std::uniform_int_distribution<int> noise(-2, 2);
  for (std::uint8_t& v : noisy.data)
    v = static_cast<std::uint8_t>(std::clamp(v + noise(*rng), 0, 255));
  return noisy;
}

}  // namespace

namespace {

SimOptions RecordingSim(const SimRecordingOptions& options) {
  SimOptions sim = SimPreset("default");
  sim.num_pairs = options.poses;
  sim.seed = options.seed;
  if (options.board.cols > 0) sim.board = options.board;
  CameraModel camera = DefaultSimCamera(false);
  const double scale = static_cast<double>(options.image_width) / camera.width;
  camera.width = options.image_width;
  camera.height = options.image_height;
  camera.fx *= scale;
  camera.fy *= scale;
  camera.cx = 0.5 * options.image_width;
  camera.cy = 0.5 * options.image_height;
  sim.camera = camera;
  sim.lidar_range_noise_m = options.lidar_range_noise_m;
  sim.min_distance_m = options.min_distance_m;
  sim.max_distance_m = options.max_distance_m;
  sim.lidar = options.lidar;
  sim.lidar_frame_s = 1.0 / options.cloud_hz;
  return ResolveSimOptions(sim);
}

}  // namespace

SimRecordingOptions SmallSimRecording(int poses) {
  SimRecordingOptions options;
  options.poses = poses;
  options.hold_s = 2.5;
  options.move_s = 1.0;
  options.image_width = 640;
  options.image_height = 360;
  options.max_distance_m = 2.5;
  return options;
}

SimRecordingTruth PlanSimRecording(const SimRecordingOptions& options) {
  const SimOptions resolved = RecordingSim(options);
  SimRecordingTruth truth;
  truth.held_cam_from_board = SampleBoardPoses(resolved);
  truth.camera = resolved.camera;
  truth.board = resolved.board;
  truth.cam_from_lidar = resolved.cam_from_lidar;
  if (options.second_camera_yaw_deg != 0.0) {
    Pose lidar_from_second = resolved.cam_from_lidar.inverse();
    lidar_from_second.linear() =
        Eigen::AngleAxisd(options.second_camera_yaw_deg * M_PI / 180.0, Vec3::UnitZ())
            .toRotationMatrix() *
        lidar_from_second.linear();
    lidar_from_second.translation() += Vec3(0.0, 0.20, 0.0);
    truth.second_cam_from_lidar = lidar_from_second.inverse();
  }
  const auto hold = static_cast<std::int64_t>(options.hold_s * kSecond);
  const auto move = static_cast<std::int64_t>(options.move_s * kSecond);
  for (int i = 0; i < options.poses; ++i) {
    truth.hold_start_ns.push_back(kStart + i * (hold + move));
    truth.hold_end_ns.push_back(truth.hold_start_ns.back() + hold);
  }
  truth.seconds = static_cast<double>(truth.hold_end_ns.back() - kStart) / kSecond;
  return truth;
}

SimRecordingTruth WriteSimRecording(RecordingWriter* writer, MessageEncoding encoding,
                                    const SimRecordingOptions& options) {
  const SimOptions resolved = RecordingSim(options);
  SimRecordingTruth truth = PlanSimRecording(options);
  const std::int64_t end = truth.hold_end_ns.back();

  BeamTable beams = MakeBeamTable(resolved.lidar);
  beams.frame_s = resolved.lidar_frame_s;
  const BoardPrint print(resolved.board);
  std::mt19937_64 rng(options.seed);
  std::uniform_real_distribution<double> phase(0.0, beams.PhaseSpanRad());
  RenderOptions still_render;  // once per hold, then noise per frame
  RenderOptions moving_render;
  moving_render.supersampling = 1;
  std::vector<ImageU8> held_images(options.poses), held_second(options.poses);

  const auto cloud_period = static_cast<std::int64_t>(kSecond / options.cloud_hz);
  const auto image_period = static_cast<std::int64_t>(kSecond / options.image_hz);
  std::int64_t next_cloud = kStart, next_image = kStart + image_period / 3;
  std::uint64_t sweep = 0;
  while (next_cloud < end || next_image < end) {
    if (next_cloud <= next_image) {
      const std::int64_t t = next_cloud;
      next_cloud += cloud_period;
      LidarScene scene;
      scene.wall_distance_m = 6.0;
      scene.lidar_from_board = truth.cam_from_lidar.inverse() * BoardAt(truth, t);
      LidarScanOptions scan;
      scan.range_noise_m = options.lidar_range_noise_m;
      // A rosette's frame is the pattern from its start time on (BeamRays: phase / 2π seconds).
      scan.azimuth_offset_rad =
          beams.risley ? 2.0 * M_PI * static_cast<double>(t - kStart) / kSecond : phase(rng);
      scan.seed = options.seed * 7919 + ++sweep;
      LidarCloud cloud = SimulateLidarScan(beams, print, scene, scan).ToCloud();
      if (options.point_times && !beams.risley)
        for (const Eigen::Vector3f& p : cloud.points) {
          const double turned =
              std::remainder(std::atan2(p.y(), p.x()) - scan.azimuth_offset_rad, 2.0 * M_PI);
          cloud.time_s.push_back(static_cast<float>((turned < 0 ? turned + 2.0 * M_PI : turned) /
                                                    (2.0 * M_PI) * cloud_period / kSecond));
        }
      // The driver stamps a sweep at its start and publishes it when complete.
      if (beams.risley) {
        const char* type = encoding == MessageEncoding::kRos1 ? "livox_ros_driver/CustomMsg"
                                                              : "livox_ros_driver2/CustomMsg";
        writer->Add({"/livox/lidar", type, t + cloud_period,
                     SerializeLivoxCustomMsg(cloud, t, "livox_frame", encoding)});
      } else {
        writer->Add({"/velodyne_points", "sensor_msgs/PointCloud2", t + cloud_period,
                     SerializePointCloud2(cloud, t, "velodyne", encoding)});
      }
      ++truth.messages;
    } else {
      const std::int64_t t = next_image;
      next_image += image_period;
      int pose = -1;
      ImageU8 image;
      if (Held(truth, t, &pose)) {
        if (held_images[pose].empty())
          held_images[pose] = RenderBoardImage(truth.camera, truth.board,
                                               truth.held_cam_from_board[pose], still_render);
        image = WithNoise(held_images[pose], &rng);
        if (pose > 0) held_images[pose - 1] = ImageU8{};
      } else {
        image = RenderBoardImage(truth.camera, truth.board, BoardAt(truth, t), moving_render);
      }
      // The camera's stamp of the instant t, on its own clock.
      const std::int64_t stamp = t + std::llround(options.camera_minus_lidar_s * 1e9);
      const std::int64_t received = stamp + 15'000'000;
      const std::string first = truth.second_cam_from_lidar ? "cam0" : "camera";
      writer->Add(
          {"/" + first + "/image_raw", "sensor_msgs/Image", received,
           SerializeImage(image, image.channels == 1 ? "mono8" : "bgr8", stamp, first, encoding)});
      writer->Add({"/" + first + "/camera_info", "sensor_msgs/CameraInfo", received,
                   SerializeCameraInfo(truth.camera, stamp, first, encoding)});
      truth.messages += 2;
      if (!truth.second_cam_from_lidar) continue;
      // The rig's second camera, triggered with the first: the same board from its mount.
      const Pose second_from_board =
          *truth.second_cam_from_lidar * truth.cam_from_lidar.inverse() * BoardAt(truth, t);
      ImageU8 second;
      if (pose >= 0) {
        if (held_second[pose].empty())
          held_second[pose] =
              RenderBoardImage(truth.camera, truth.board, second_from_board, still_render);
        second = WithNoise(held_second[pose], &rng);
        if (pose > 0) held_second[pose - 1] = ImageU8{};
      } else {
        second = RenderBoardImage(truth.camera, truth.board, second_from_board, moving_render);
      }
      writer->Add({"/cam1/image_raw", "sensor_msgs/Image", received,
                   SerializeImage(second, second.channels == 1 ? "mono8" : "bgr8", stamp, "cam1",
                                  encoding)});
      writer->Add({"/cam1/camera_info", "sensor_msgs/CameraInfo", received,
                   SerializeCameraInfo(truth.camera, stamp, "cam1", encoding)});
      truth.messages += 2;
    }
  }
  return truth;
}

WavedDataset WriteWavedRecording(RecordingWriter* writer, MessageEncoding encoding,
                                 WaveOptions wave, const std::filesystem::path& scratch,
                                 PointLayout layout) {
  wave.every_sweep = true;
  const WavedDataset waved = SimulateWavedDataset(wave, scratch);
  const std::int64_t sweep_ns = std::llround(1e9 / wave.lidar_hz);
  const bool ouster = layout == PointLayout::kOuster;
  const bool livox = MakeBeamTable(wave.rig.lidar).risley.has_value();
  std::vector<RecordedMessage> messages;
  for (const auto& [file, stamp] : waved.sweep_files) {
    const LidarCloud cloud = LoadCloud(file);
    if (livox) {
      // livox_ros_driver's CustomMsg: each point's offset_time (ns) after the frame's timebase.
      std::vector<std::uint32_t> offsets_ns;
      for (const float t : cloud.time_s)
        offsets_ns.push_back(static_cast<std::uint32_t>(std::llround(t * 1e9)));
      messages.push_back(
          {"/livox/lidar",
           encoding == MessageEncoding::kRos1 ? "livox_ros_driver/CustomMsg"
                                              : "livox_ros_driver2/CustomMsg",
           stamp + sweep_ns,
           SerializeLivoxCustomMsg(cloud, stamp, "livox_frame", encoding, offsets_ns)});
      continue;
    }
    messages.push_back({ouster ? "/os_cloud_node/points" : "/velodyne_points",
                        "sensor_msgs/PointCloud2", stamp + sweep_ns,
                        SerializePointCloud2(cloud, stamp, ouster ? "os_sensor" : "velodyne",
                                             encoding, false, "ring", layout)});
  }
  for (const StampedImage& frame : waved.frame_files) {
    const ImageU8 image = LoadImage(frame.image);
    const std::int64_t received = frame.stamp_ns + 15'000'000;
    messages.push_back({"/camera/image_raw", "sensor_msgs/Image", received,
                        SerializeImage(image, image.channels == 1 ? "mono8" : "bgr8",
                                       frame.stamp_ns, "camera", encoding)});
    messages.push_back(
        {"/camera/camera_info", "sensor_msgs/CameraInfo", received,
         SerializeCameraInfo(waved.dataset.camera, frame.stamp_ns, "camera", encoding)});
  }
  std::stable_sort(messages.begin(), messages.end(),
                   [](const auto& a, const auto& b) { return a.log_time_ns < b.log_time_ns; });
  for (const RecordedMessage& message : messages) writer->Add(message);
  return waved;
}

}  // namespace calibench::test
