// The panels below the views: the measurements list and the solver.
#include <imgui.h>

#include <algorithm>
#include <string>
#include <type_traits>
#include <variant>

#include "core/estimation/uncertainty.h"
#include "core/lidar_camera/result_io.h"
#include "ui/lidar_camera/workbench.h"
#include "ui/lidar_camera/workbench_gl.h"
#include "ui/widgets/export_row.h"
#include "ui/widgets/pair_review.h"
#include "ui/widgets/path_field.h"
#include "ui/widgets/solution_readouts.h"

namespace calibench::ui {
namespace {

constexpr float kThumbHeight = 36.0f;  // pixels: the height of a row of the pairs table

constexpr SolverMethod kMethods[] = {SolverMethod::kWeightedMl, SolverMethod::kCa2libGn,
                                     SolverMethod::kKim};
constexpr const char* kMethodHelp[] = {
    "weighted-ml: both planes' covariances whiten the residual (default)",
    "ca2lib-gn: the paper's unweighted plane-to-plane Gauss-Newton",
    "kim: closed form from the normals (Kim et al. 2020), no refinement"};

// The solver method, with what each does; a change is an intent. Returns the method's index.
int MethodCombo(const JobSettings& settings, std::vector<Intent>* intents) {
  int method_index = 0;
  for (int i = 0; i < 3; ++i)
    if (kMethods[i] == settings.method) method_index = i;
  SolverMethod method = settings.method;
  ImGui::SetNextItemWidth(140);
  if (ImGui::BeginCombo("method", SolverMethodName(settings.method).c_str())) {
    for (int i = 0; i < 3; ++i) {
      if (ImGui::Selectable(SolverMethodName(kMethods[i]).c_str(), i == method_index))
        method = kMethods[i];
      if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", kMethodHelp[i]);
    }
    ImGui::EndCombo();
  }
  if (method != settings.method) {
    JobSettings changed = settings;
    changed.method = method;
    intents->push_back(SetSettings{changed});
  }
  return method_index;
}

// Method, range offset, Huber delta and iterations; each change an intent.
void SolverOptionsRows(const Snapshot& s, std::vector<Intent>* intents) {
  const JobSettings& shown = s.settings;
  const int method_index = MethodCombo(shown, intents);
  JobSettings edited = shown;
  ImGui::SameLine();
  ImGui::BeginDisabled(shown.method != SolverMethod::kWeightedMl);
  if (ImGui::Checkbox("range offset", &edited.estimate_range_offset))
    intents->push_back(SetSettings{edited});
  if (ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled))
    ImGui::SetTooltip(
        "weighted-ml: also estimate a constant LiDAR range offset (measured = true + offset),\n"
        "reported with its standard deviation and its correlation with the translation");
  ImGui::EndDisabled();
  ImGui::SameLine();
  ImGui::TextDisabled("%s", kMethodHelp[method_index]);
  ImGui::SetNextItemWidth(120);
  // The settings with an input of their own (JobSettingFields' labels) on one line; their
  // edits count once done, without the checkbox's.
  edited = shown;
  bool done = false, first = true;
  for (const JobSettingField& field : JobSettingFields()) {
    if (field.label.empty()) continue;
    if (!first) ImGui::SameLine();
    first = false;
    const std::string label(field.label);
    ImGui::SetNextItemWidth(110);
    std::visit(
        [&](auto slot) {
          auto& value = edited.*slot.setting;
          using Value = std::remove_reference_t<decltype(value)>;
          if constexpr (std::is_same_v<Value, double>)
            ImGui::InputDouble(label.c_str(), &value, 0.01, 0.1, "%.3f");
          else if constexpr (std::is_same_v<Value, int>)
            ImGui::InputInt(label.c_str(), &value);
        },
        field.slot);
    done = done || ImGui::IsItemDeactivatedAfterEdit();
  }
  if (done) intents->push_back(SetSettings{edited});
}

// Iteration, cost and step length of each iteration, the shown one highlighted.
void IterationsTable(const std::vector<IterationReport>& iterations, int shown) {
  if (!ImGui::BeginTable("iterations", 3, ImGuiTableFlags_ScrollY | ImGuiTableFlags_RowBg,
                         ImVec2(0, 70)))
    return;
  ImGui::TableSetupColumn("it");
  ImGui::TableSetupColumn("cost");
  ImGui::TableSetupColumn("|step|");
  ImGui::TableHeadersRow();
  for (const IterationReport& it : iterations) {
    ImGui::TableNextRow();
    ImGui::TableNextColumn();
    if (it.iteration == shown)
      ImGui::TextColored({1, 0.85f, 0.3f, 1}, "%d", it.iteration);
    else
      ImGui::Text("%d", it.iteration);
    ImGui::TableNextColumn();
    ImGui::Text("%.4e", it.cost);
    ImGui::TableNextColumn();
    ImGui::Text("%.2e", it.step_norm);
  }
  ImGui::EndTable();
}

// What the solve estimated besides the pose: the range offset, the board edges' dilation, how
// far the pairs' spread widened the covariance.
void SolveExtras(const SolverResult& res) {
  if (res.covariance_inflation > 1.0)
    ImGui::TextWrapped(
        "std widened by the spread over the pairs (variance x%.1f): the noise "
        "models underestimate this data",
        res.covariance_inflation);
  if (res.range_offset) {
    const Vec3& c = res.range_offset->correlation_with_translation;
    ImGui::Text("range offset: %+.1f ± %.1f mm (correlation with translation %.2f %.2f %.2f)",
                res.range_offset->value_m * 1e3, res.range_offset->sigma_m * 1e3, c.x(), c.y(),
                c.z());
  }
  if (res.edge_dilation) {
    ImGui::Text("board edges: %d crossings, sheet seen %+.1f ± %.1f mm larger per side",
                res.num_edge_residuals, res.edge_dilation->value_m * 1e3,
                res.edge_dilation->sigma_m * 1e3);
  }
}

}  // namespace

void Workbench::MeasurementsPanel(const Snapshot& s, const Rect& r, std::vector<Intent>* intents) {
  if (!BeginPanel("Measurements", r)) return ImGui::End();
  if (s.rig && s.rig->Several()) RigStrip(s, intents);
  PairProgress("loading", s.loading_done, s.loading_total);
  if (const auto status =
          ReviewButtons(s.selected >= 0, "arrows: previous / next   ctrl+z / ctrl+y: undo / redo"))
    intents->push_back(SetPairStatus{s.selected, *status});
  if (BeginPairsTable({{"image", kThumbHeight * 4 / 3 + 4},
                       {"pair", 70},
                       {"status", 70},
                       {"|e|", 60},
                       {"weight", 50},
                       {"details"}})) {
    for (int i = 0; i < static_cast<int>(s.pairs.size()); ++i) PairRow(s, i, intents);
    listed_selection_ = s.selected;
    ImGui::EndTable();
  }
  ImGui::End();
}

// Thumbnail, id (selects the pair), status, residual, robust weight, what the pair gave.
namespace {

// The finding that matters most (a rejection before a weakness), or null.
const PreflightFinding* WorstFinding(const std::vector<PreflightFinding>& findings) {
  const PreflightFinding* worst = nullptr;
  for (const PreflightFinding& f : findings)
    if (!worst ||
        (f.severity == PreflightSeverity::kReject && worst->severity != PreflightSeverity::kReject))
      worst = &f;
  return worst;
}

}  // namespace

void Workbench::PairRow(const Snapshot& s, int index, std::vector<Intent>* intents) {
  const PairView& pair = s.pairs[index];
  ImGui::TableNextRow(0, kThumbHeight);
  ImGui::TableNextColumn();
  if (pair.thumbnail) {
    auto& texture = gl_->thumbnails[pair.id];
    if (!texture) {
      texture = std::make_unique<gfx::ImageTexture>();
      texture->Upload(*pair.thumbnail, true);
    }
    const float tw = kThumbHeight * pair.thumbnail->width / std::max(1, pair.thumbnail->height);
    ImGui::Image(TextureId(texture->texture()), ImVec2(tw, kThumbHeight));
  }
  ImGui::TableNextColumn();
  if (PairSelectable(index, pair.id, index == s.selected, kThumbHeight))
    intents->push_back(SelectPair{index});
  // A selection made elsewhere (keys, a followed capture's newest pair) scrolls into view.
  if (index == s.selected && s.selected != listed_selection_ && !ImGui::IsItemVisible())
    ImGui::SetScrollHereY(1.0f);
  ImGui::TableNextColumn();
  PairStatusText(pair.status, pair.loaded ? PairStatusName(pair.status) : "loading");
  ImGui::TableNextColumn();
  if (pair.residual) ImGui::Text("%.4f", pair.residual->norm());
  ImGui::TableNextColumn();
  if (pair.residual) {
    if (pair.robust_weight < 0.999)
      ImGui::TextColored({1.0f, 0.55f, 0.3f, 1}, "%.2f", pair.robust_weight);
    else
      ImGui::Text("%.2f", pair.robust_weight);
  }
  ImGui::TableNextColumn();
  const double negligible =
      s.solver.result ? s.solver.result->negligible_weight : SolverOptions{}.negligible_weight;
  if (pair.residual && pair.status == PairStatus::kAccepted && pair.robust_weight < negligible) {
    ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1.0f, 0.55f, 0.3f, 1));
    ImGui::TextWrapped(
        "down-weighted to nothing: its planes disagree with the others', in effect left out of "
        "the solve");
    ImGui::PopStyleColor();
  } else if (!pair.reason.empty()) {
    ImGui::TextWrapped("%s", pair.reason.c_str());
    // Why the camera missed a board the LiDAR placed (advise's "reach" finding).
    for (const PreflightFinding& f : pair.findings) {
      if (f.check != "reach") continue;
      ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(0.95f, 0.85f, 0.4f, 1));
      ImGui::TextWrapped("%s", f.words.c_str());
      ImGui::PopStyleColor();
    }
  } else if (const PreflightFinding* finding = WorstFinding(pair.findings)) {
    // Pre-flight's word on an accepted pair (rejections apply by themselves only while a
    // capture is followed; on a dataset the user decides).
    ImGui::PushStyleColor(ImGuiCol_Text, finding->severity == PreflightSeverity::kReject
                                             ? ImVec4(1.0f, 0.55f, 0.3f, 1)
                                             : ImVec4(0.95f, 0.85f, 0.4f, 1));
    ImGui::TextWrapped("pre-flight%s: %s",
                       finding->severity == PreflightSeverity::kReject ? " would reject" : "",
                       finding->words.c_str());
    ImGui::PopStyleColor();
  } else if (pair.lidar && pair.camera) {
    ImGui::TextDisabled("%zu inliers, %.1f mm | %d corners, %.2f px", pair.lidar->inliers.size(),
                        pair.lidar->rms_m * 1e3, pair.camera->num_corners,
                        pair.camera->reprojection_rms_px);
  }
}

void Workbench::SolverPanel(const Snapshot& s, const Rect& r, std::vector<Intent>* intents) {
  if (!BeginPanel("Solver", r)) return ImGui::End();
  SolverOptionsRows(s, intents);
  const SolverReplay::Request request =
      replay().Buttons(s.solver.iterations.size(), s.solver.running);
  if (request.run) intents->push_back(RunSolver{});
  if (request.reset) intents->push_back(ResetSolver{});
  ImGui::SameLine();
  if (ImGui::Button("Camera intrinsics...")) intrinsics_open_ = !intrinsics_open_;
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip(
        "estimate the camera's intrinsics from the loaded pairs: coverage, per-image "
        "error, sigma");
  ImGui::SameLine();
  if (ImGui::Button("Targetless check...")) check_open_ = !check_open_;
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip(
        "is the calibration still right? check it against the scene's edges, without a board");
  MeterRows(s, intents);
  if (s.rig && s.rig->Several()) RigMeterRows(s, intents);
  if (!s.solver.iterations.empty()) {
    replay().CostPlot(s.solver.iterations, ImVec2(r.w * 0.45f, 70));
    ImGui::SameLine();
    IterationsTable(s.solver.iterations, replay().Shown(s.solver.iterations.size()));
  }
  // While a capture is followed, too few pairs yet is where every capture starts, not an error.
  if (!s.solver.failure.empty() && !s.watching.empty() && !s.status_is_error)
    ImGui::TextDisabled("%s", s.solver.failure.c_str());
  else if (!s.solver.failure.empty())
    ImGui::TextColored({1.0f, 0.4f, 0.35f, 1}, "%s", s.solver.failure.c_str());
  if (s.solver.result) SolutionReadouts(s.solver, intents);
  if (PathField("##session", &session_path_, "Save session as"))
    intents->push_back(SaveSessionAs{session_path_});
  ImGui::End();
  if (intrinsics_open_) IntrinsicsWindow(s, intents);
  if (check_open_) CheckWindow(s, intents);
  if (!s.board_problem.empty())
    BoardPicker(s, intents);
  else
    picker_frames_ = 0;
}

void Workbench::SolutionReadouts(const SolverView& solver, std::vector<Intent>* intents) {
  const SolverResult& res = *solver.result;
  // First, so that it is seen without scrolling: the estimate below leaves it out.
  if (res.unmodelled_range_offset)
    ImGui::TextColored({1.0f, 0.75f, 0.3f, 1},
                       "the data shows a LiDAR range offset of %+.1f ± %.1f mm that this solve "
                       "left out: tick \"range offset\" and solve again",
                       res.unmodelled_range_offset->value_m * 1e3,
                       res.unmodelled_range_offset->sigma_m * 1e3);
  PoseReadout("cam_from_lidar", "x_cam = T * x_lidar", res.cam_from_lidar);
  PoseReadout("lidar_from_cam", "camera position and axes in the LiDAR frame",
              res.cam_from_lidar.inverse());
  StdReadout(TranslationStd(res.covariance, res.cam_from_lidar) * 1000.0,
             RotationStdDeg(res.covariance, res.cam_from_lidar));
  SolveExtras(res);
  ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(0.7f, 0.75f, 0.8f, 1));
  for (const std::string& note : solver.notes) ImGui::TextWrapped("%s", note.c_str());
  ImGui::PopStyleColor();
  if (!solver.targetless_provenance.empty())
    ImGui::TextColored({1.0f, 0.72f, 0.3f, 1}, "targetless estimate, not a board solve");
  ObservabilityReadout(
      res.observability,
      std::to_string(res.iterations) + " iterations, " + res.termination.Describe(),
      "NOT well constrained: add pairs with other board tilts");
  if (ExportRow(&export_))
    intents->push_back(ExportResult{export_.path, export_.format, export_.frames});
}

}  // namespace calibench::ui
