// The workbench's view state (ui/state/view_state.h): the session file's "view" object, which
// core keeps as text and the workbench alone reads.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "core/base/types.h"
#include "core/session/session.h"
#include "tests/test_support.h"
#include "ui/state/view_state.h"

namespace calibench::ui {
namespace {

const std::vector<std::string> kPairs = {"0000", "0001", "0002"};

ViewState EveryFieldSet() {
  ViewState v;
  v.selected_pair = "0002";
  v.lidar_channel = LidarChannel::kRing;
  v.camera_image = CameraImageMode::kRaw;
  v.visibility = VisibilityMode::kZBuffer;
  v.hpr_radius_exponent = 3.0000000000000004;
  v.point_size_px = 3.5;
  v.point_opacity = 0.7;
  v.orbit_yaw_rad = -2.718281828459045;
  v.orbit_pitch_rad = 1e-300;
  v.orbit_distance_m = 123456.789;
  v.orbit_target = {0.1, -5e-324, 7.0};
  v.brush_radius_px = 11.25;
  return v;
}

// Through a session file and back: every field exactly, the text unchanged by a second save.
TEST(ViewState, EveryFieldRoundTripsThroughTheSessionFile) {
  const auto dir = test::TempDir("view_state");
  Session session;
  session.dataset = dir / "dataset.json";
  for (const std::string& id : kPairs) session.pairs.emplace_back().id = id;
  session.view_json = ViewToJson(EveryFieldSet());
  SaveSession(dir / "s.json", session);
  const Session loaded = LoadSession(dir / "s.json");
  EXPECT_EQ(loaded, session);
  EXPECT_EQ(ViewFromJson(loaded.view_json, dir / "s.json", kPairs), EveryFieldSet());

  ViewState odd = EveryFieldSet();
  odd.orbit_yaw_rad = std::numeric_limits<double>::quiet_NaN();
  odd.orbit_target[1] = -std::numeric_limits<double>::infinity();
  const ViewState back = ViewFromJson(ViewToJson(odd), "s.json", kPairs);
  EXPECT_TRUE(std::isnan(back.orbit_yaw_rad));
  EXPECT_EQ(back.orbit_target[1], -std::numeric_limits<double>::infinity());
}

TEST(ViewState, ANewSessionsEmptyViewSelectsTheFirstPair) {
  const ViewState view = ViewFromJson("{}", "s.json", kPairs);
  EXPECT_EQ(view.selected_pair, "0000");
  ViewState expected;
  expected.selected_pair = "0000";
  EXPECT_EQ(view, expected);
}

void ExpectRejected(const std::string& text, const std::string& problem) {
  try {
    ViewFromJson(text, "/data/calibench.session.json", kPairs);
    ADD_FAILURE() << "read a broken view; expected: " << problem;
  } catch (const IoError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("/data/calibench.session.json"), std::string::npos) << message;
    EXPECT_NE(message.find(problem), std::string::npos) << message;
  }
}

TEST(ViewState, AMalformedViewNamesTheFileAndTheField) {
  ExpectRejected(R"({"point_opacity": 1.5})", "view.point_opacity: must lie in [0, 1]");
  ExpectRejected(R"({"selected_pair": "9"})", "view.selected_pair: \"9\" is not a pair");
  ExpectRejected(R"({"visibility": "sometimes"})", "view.visibility");
  ExpectRejected(R"({"orbit_target_m": [1, 2]})", "view.orbit_target_m");
  ExpectRejected(R"({"point_size_px": -1})", "view.point_size_px");
  ExpectRejected("[1]", "must be a JSON object");
}

// FramedOn: the target on the centre, looking from the LiDAR's side (behind its x axis as in
// front of it), as far as a sphere of the radius fills the 0.9 rad view; pitch and the rest kept.
TEST(ViewState, FramingLooksAtTheCentreFromTheLidarsSide) {
  ViewState view = EveryFieldSet();
  const ViewState framed = FramedOn(view, {-1.5, 0.0, -0.4}, 1.0);
  EXPECT_EQ(framed.orbit_target, (std::array<double, 3>{-1.5, 0.0, -0.4}));
  EXPECT_NEAR(std::abs(framed.orbit_yaw_rad), M_PI, 1e-12);  // looking along -x
  EXPECT_NEAR(framed.orbit_distance_m, 1.0 / std::sin(0.45), 1e-12);
  EXPECT_EQ(framed.orbit_pitch_rad, view.orbit_pitch_rad);
  EXPECT_EQ(framed.point_size_px, view.point_size_px);
  EXPECT_EQ(framed.selected_pair, view.selected_pair);
  EXPECT_NEAR(FramedOn(view, {0.0, 2.0, 0.0}, 1.0).orbit_yaw_rad, M_PI / 2, 1e-12);
  // Straight above the LiDAR the bearing says nothing: the yaw stays; the distance is clamped.
  const ViewState above = FramedOn(view, {0.05, 0.0, 3.0}, 1e4);
  EXPECT_EQ(above.orbit_yaw_rad, view.orbit_yaw_rad);
  EXPECT_EQ(above.orbit_distance_m, 200.0);
  EXPECT_EQ(FramedOn(view, {1.0, 0.0, 0.0}, 0.01).orbit_distance_m, 0.5);
}

}  // namespace
}  // namespace calibench::ui
