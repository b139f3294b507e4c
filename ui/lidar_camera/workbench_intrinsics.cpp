// The camera-intrinsics window: the loaded pairs' corners calibrate the camera (EstimateIntrinsics,
// the step `calibench intrinsics` runs); shown are the coverage map (corners per image cell, the
// empty ones red, where the distortion is not seen), every image's error, each parameter with its
// σ and the stop rule's verdict; the result is written beside the dataset on request.
#include <imgui.h>

#include <algorithm>
#include <cmath>

#include "ui/lidar_camera/workbench.h"
#include "ui/widgets/path_field.h"

namespace calibench::ui {
namespace {

constexpr const char* kModels[] = {"pinhole", "fisheye"};
constexpr const char* kFormats[] = {"ros", "opencv", "kalibr"};
constexpr CameraFileFormat kFormatValues[] = {CameraFileFormat::kRosCameraInfo,
                                              CameraFileFormat::kOpenCv, CameraFileFormat::kKalibr};
const ImVec4 kGood(0.45f, 0.85f, 0.45f, 1), kNotYet(1.0f, 0.7f, 0.3f, 1);

// The image as a grid of cells coloured by their corners (none: red), every pair's corners as
// dots over it; `width` pixels wide at the image's aspect.
void CoverageMap(const Snapshot& s, const IntrinsicsCoverage& coverage, float width) {
  const CameraModel& camera = s.dataset->camera;
  const float scale = width / static_cast<float>(camera.width);
  const ImVec2 size(width, scale * static_cast<float>(camera.height));
  const ImVec2 origin = ImGui::GetCursorScreenPos();
  ImDrawList* draw = ImGui::GetWindowDrawList();
  const int most = std::max(1, *std::max_element(coverage.counts.begin(), coverage.counts.end()));
  const float cell_w = size.x / coverage.columns, cell_h = size.y / coverage.rows;
  for (int j = 0; j < coverage.rows; ++j) {
    for (int i = 0; i < coverage.columns; ++i) {
      const int count = coverage.counts[static_cast<size_t>(j * coverage.columns + i)];
      const ImVec2 a(origin.x + i * cell_w, origin.y + j * cell_h);
      const ImVec2 b(a.x + cell_w, a.y + cell_h);
      const float share = std::sqrt(static_cast<float>(count) / most);
      draw->AddRectFilled(a, b,
                          count == 0 ? IM_COL32(150, 40, 35, 255)
                                     : IM_COL32(30, static_cast<int>(60 + 120 * share), 55, 255));
      draw->AddRect(a, b, IM_COL32(20, 20, 20, 255));
    }
  }
  for (const PairView& pair : s.pairs) {
    if (!pair.detection) continue;
    for (const Vec2& p : pair.detection->pixels)
      draw->AddCircleFilled(ImVec2(origin.x + scale * static_cast<float>(p.x()),
                                   origin.y + scale * static_cast<float>(p.y())),
                            1.5f, IM_COL32(235, 235, 235, 200));
  }
  ImGui::Dummy(size);
}

// Each parameter with its σ and the stop rule's relative 95 % interval.
void ParameterTable(const IntrinsicsResult& r) {
  if (!ImGui::BeginTable("parameters", 4, ImGuiTableFlags_RowBg | ImGuiTableFlags_SizingFixedFit))
    return;
  for (const char* header : {"parameter", "value", "sigma", "1.96 sigma / value"})
    ImGui::TableSetupColumn(header);
  ImGui::TableHeadersRow();
  for (size_t i = 0; i < r.parameters.size(); ++i) {
    ImGui::TableNextRow();
    ImGui::TableNextColumn();
    ImGui::TextUnformatted(r.parameter_names[i].c_str());
    ImGui::TableNextColumn();
    ImGui::Text("%.6g", r.parameters[i]);
    ImGui::TableNextColumn();
    ImGui::Text("%.3g", r.sigmas[i]);
    ImGui::TableNextColumn();
    const double relative =
        r.parameters[i] != 0 ? 1.96 * r.sigmas[i] / std::abs(r.parameters[i]) : 0.0;
    if (i < 4)
      ImGui::TextColored(relative < 0.05 ? kGood : kNotYet, "%.2f %%", 100 * relative);
    else
      ImGui::TextDisabled("%.1f %%", 100 * relative);
  }
  ImGui::EndTable();
}

// Every image: its corners, its RMS as a bar against the worst, used or why not.
void ImageTable(const IntrinsicsResult& r) {
  double worst = 0.0;
  for (const IntrinsicsImage& image : r.images) worst = std::max(worst, image.rms_px);
  if (!ImGui::BeginTable(
          "images", 4,
          ImGuiTableFlags_RowBg | ImGuiTableFlags_ScrollY | ImGuiTableFlags_SizingFixedFit,
          ImVec2(0, 220)))
    return;
  ImGui::TableSetupScrollFreeze(0, 1);
  for (const char* header : {"image", "corners", "RMS px", "used"}) ImGui::TableSetupColumn(header);
  ImGui::TableHeadersRow();
  for (const IntrinsicsImage& image : r.images) {
    ImGui::TableNextRow();
    ImGui::TableNextColumn();
    ImGui::TextUnformatted(image.name.c_str());
    ImGui::TableNextColumn();
    ImGui::Text("%d", image.corners);
    ImGui::TableNextColumn();
    char label[32];
    std::snprintf(label, sizeof(label), "%.3f", image.rms_px);
    ImGui::ProgressBar(worst > 0 ? static_cast<float>(image.rms_px / worst) : 0.0f, ImVec2(110, 0),
                       label);
    ImGui::TableNextColumn();
    if (image.used)
      ImGui::TextUnformatted("used");
    else
      ImGui::TextColored(kNotYet, "%s", image.reason.c_str());
  }
  ImGui::EndTable();
}

}  // namespace

void Workbench::IntrinsicsWindow(const Snapshot& s, std::vector<Intent>* intents) {
  ImGui::SetNextWindowSize(ImVec2(560, 760), ImGuiCond_FirstUseEver);
  if (!ImGui::Begin("Camera intrinsics", &intrinsics_open_)) return ImGui::End();
  if (!s.dataset) {
    ImGui::TextDisabled("open a dataset first");
    return ImGui::End();
  }
  if (intrinsics_model_ < 0)
    intrinsics_model_ = s.dataset->camera.type == CameraModelType::kKannalaBrandt ? 1 : 0;
  int with_corners = 0;
  for (const PairView& pair : s.pairs) with_corners += pair.detection.has_value();
  ImGui::SetNextItemWidth(100);
  ImGui::Combo("model", &intrinsics_model_, kModels, 2);
  ImGui::SameLine();
  ImGui::BeginDisabled(s.intrinsics_running || with_corners == 0);
  char button[96];
  std::snprintf(button, sizeof(button), "Estimate from the loaded pairs (%d with corners)",
                with_corners);
  if (ImGui::Button(button))
    intents->push_back(EstimateIntrinsics{intrinsics_model_ == 1
                                              ? CameraModelType::kKannalaBrandt
                                              : CameraModelType::kPinholeRadTan});
  ImGui::EndDisabled();
  if (s.intrinsics_running) ImGui::TextDisabled("estimating...");
  if (!s.intrinsics_failure.empty())
    ImGui::TextColored({1.0f, 0.4f, 0.35f, 1}, "%s", s.intrinsics_failure.c_str());
  if (!s.intrinsics) {
    ImGui::TextWrapped("The dataset's camera: fx %.2f fy %.2f cx %.2f cy %.2f (%s).",
                       s.dataset->camera.fx, s.dataset->camera.fy, s.dataset->camera.cx,
                       s.dataset->camera.cy, CameraModelName(s.dataset->camera.type).c_str());
    return ImGui::End();
  }
  const IntrinsicsResult& r = *s.intrinsics;
  ImGui::PushTextWrapPos(0);
  ImGui::TextColored(r.good ? kGood : kNotYet, "%s", r.verdict.c_str());
  ImGui::PopTextWrapPos();
  ImGui::Text("RMS %.3f px; the dataset's camera: fx %.2f fy %.2f cx %.2f cy %.2f", r.rms_px,
              s.dataset->camera.fx, s.dataset->camera.fy, s.dataset->camera.cx,
              s.dataset->camera.cy);
  ParameterTable(r);
  ImGui::Text("coverage: %.0f %% of the %dx%d cells, %.0f %% of the border (red: no corner)",
              100 * r.coverage.cells_covered, r.coverage.columns, r.coverage.rows,
              100 * r.coverage.border_covered);
  CoverageMap(s, r.coverage, std::min(ImGui::GetContentRegionAvail().x, 520.0f));
  ImageTable(r);
  ImGui::SetNextItemWidth(80);
  ImGui::Combo("format", &intrinsics_format_, kFormats, 3);
  ImGui::SameLine();
  if (PathField("##intrinsics_path", &intrinsics_path_, "Save beside the dataset"))
    intents->push_back(SaveIntrinsics{intrinsics_path_, kFormatValues[intrinsics_format_]});
  if (!s.intrinsics_saved.empty()) ImGui::TextDisabled("saved: %s", s.intrinsics_saved.c_str());
  ImGui::End();
}

}  // namespace calibench::ui
