// `calibench watch --check R RECORDING`: the drift meter (core/targetless/check_follow.h) on a
// recording being written — a drive after calibration: the targetless estimate and its σ over the
// frames so far, the verdict once it is sure.
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <thread>

#include "app/commands.h"
#include "app/machine_stdout.h"
#include "core/capture/recording_watch.h"
#include "core/io/camera_file.h"
#include "core/targetless/check_follow.h"
#include "core/targetless/check_output.h"
#include "core/targetless/checked_calibration.h"

namespace calibench::app {

namespace {

std::string DriftLine(const DriftUpdate& update) {
  const CheckReport& r = *update.report;
  char line[512];
  if (!r.has_estimate) {
    std::snprintf(line, sizeof line, "%d frames: %s (no estimate yet)\n", update.frames_seen,
                  CheckVerdictName(r.verdict).c_str());
    return line;
  }
  std::snprintf(line, sizeof line,
                "%d frames: change %.2f deg / %.1f mm (sigma %.2f / %.2f / %.2f deg, %.1f / %.1f / "
                "%.1f mm) -> %s%s\n",
                update.frames_seen, r.change_r_deg.norm(), 1e3 * r.change_t_m.norm(),
                r.sigma_r_deg.x(), r.sigma_r_deg.y(), r.sigma_r_deg.z(), 1e3 * r.sigma_t_m.x(),
                1e3 * r.sigma_t_m.y(), 1e3 * r.sigma_t_m.z(), CheckVerdictName(r.verdict).c_str(),
                update.sure ? " (sure: the same at two checks in a row)" : " (not sure yet)");
  return line;
}

std::string DriftJson(const DriftUpdate& update, const char* event) {
  nlohmann::json j = update.report ? nlohmann::json::parse(CheckReportJson(*update.report))
                                   : nlohmann::json::object();
  j["event"] = event;
  j["frames_seen"] = update.frames_seen;
  j["frames_held"] = update.frames;
  j["sure"] = update.sure;
  return j.dump();
}

}  // namespace

void AddDriftMeterFlags(CLI::App& app, WatchCheckRequest* request) {
  app.add_option("--check", request->result,
                 "recordings: no board capture; the drift meter instead: this calibration "
                 "(result file or session) judged without a target over the frames so far (as "
                 "`calibench check`), the verdict once it is sure (--exit-when-done: end then)");
  app.add_option("--check-every", request->drift.recheck_every,
                 "with --check: check again after this many new frames")
      ->capture_default_str();
}

int WatchCheck(WatchCheckRequest request) {
  if (!request.camera_file.empty()) request.input.camera = LoadCameraFile(request.camera_file);
  std::string why;
  if (!request.drift.Check(&why) || !request.input.Check(&why) || !(request.idle_exit_s >= 0)) {
    std::fprintf(stderr, "calibench watch: %s\n",
                 why.empty() ? "--idle-exit must be >= 0 (seconds)" : why.c_str());
    return kUsage;
  }
  const CheckedCalibration checked = LoadCheckedCalibration(request.result);
  const Pose& reference = checked.cam_from_lidar;
  const Mat6& reference_covariance = checked.camera_axes_covariance;
  if (!IsRecordingSource(request.source)) {
    std::fprintf(stderr,
                 "calibench watch: --check follows a recording being written (.bag, .mcap, "
                 ".db3, a rosbag2 folder); %s is not one. For a folder of scenes: calibench "
                 "check --dataset %s --result %s\n",
                 request.source.c_str(), request.source.c_str(), request.result.c_str());
    return kUsage;
  }
  DriftMeter meter(request.source, reference, reference_covariance, request.check, request.input,
                   request.drift);
  MachineStdout out(request.json_lines);
  auto last_data = std::chrono::steady_clock::now();
  std::optional<DriftUpdate> last_report;
  bool said_sure = false;
  for (;;) {
    DriftUpdate update = meter.Poll();
    for (const std::string& note : update.notes)
      std::fprintf(stderr, "calibench watch: %s\n", note.c_str());
    if (update.data_arrived) last_data = std::chrono::steady_clock::now();
    if (update.new_frames > 0)
      std::fprintf(stderr, "calibench watch: %d frames so far\n", update.frames_seen);
    if (update.report) {
      if (request.json_lines)
        out.Print(DriftJson(update, "drift"));
      else
        std::printf("%s", DriftLine(update).c_str());
      std::fflush(stdout);
      if (update.sure && !said_sure && !request.json_lines)
        std::printf("verdict: %s\nwhy: %s\n", CheckVerdictName(update.report->verdict).c_str(),
                    update.report->why.c_str());
      said_sure = said_sure || update.sure;
      last_report = update;
    }
    const bool idle =
        request.idle_exit_s > 0 &&
        std::chrono::duration<double>(std::chrono::steady_clock::now() - last_data).count() >
            request.idle_exit_s;
    if (update.closed || idle || (request.exit_when_sure && update.sure)) {
      const char* why = update.closed ? "the recorder closed the file"
                        : idle        ? "no new data within --idle-exit"
                                      : "the verdict is sure";
      if (request.json_lines) {
        DriftUpdate end = last_report ? *last_report : update;
        nlohmann::json j = nlohmann::json::parse(DriftJson(end, "end"));
        j["ended_because"] = why;
        out.Print(j.dump());
      } else if (last_report) {
        std::printf("end (%s): %s after %d frames%s\nwhy: %s\n", why,
                    CheckVerdictName(last_report->report->verdict).c_str(),
                    last_report->frames_seen, last_report->sure ? " (sure)" : " (not sure)",
                    last_report->report->why.c_str());
      } else {
        std::printf("end (%s): no check ran (too few frames)\n", why);
      }
      return kOk;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }
}

}  // namespace calibench::app
