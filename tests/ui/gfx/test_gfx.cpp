// ui/gfx on headless contexts: a known scene drawn into a Framebuffer and checked pixel by pixel
// against hand-computed projections, the same scene drawn by EGL and by OSMesa and compared (two
// render paths, no stored image), read-back orientation and resizing.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <limits>
#include <numbers>
#include <optional>
#include <random>

#include "core/base/image.h"
#include "core/io/image_io.h"
#include "tests/test_support.h"
#include "ui/gfx/context.h"
#include "ui/gfx/framebuffer.h"
#include "ui/gfx/gl_api.h"  // first GL header of this file: glGetError for the checks
#include "ui/gfx/point_splat.h"
#include "ui/gfx/renderers.h"
#include "ui/gfx/scene_layers.h"

namespace calibench::gfx {
namespace {

bool GlRequired() {
  const char* env = std::getenv("CALIBENCH_REQUIRE_GL");
  return env && std::string(env) == "1";
}

// Binds `context` to a current headless context of `backend`. When the backend is unavailable:
// GTEST_SKIP with the reason, or a failure under CALIBENCH_REQUIRE_GL=1 (as CI sets it).
#define CALIBENCH_REQUIRE_GL_CONTEXT(context, backend)                                       \
  std::string context##_why;                                                                 \
  const std::unique_ptr<GlContext> context = CreateHeadlessContext(backend, &context##_why); \
  if (!context) {                                                                            \
    if (GlRequired()) FAIL() << "CALIBENCH_REQUIRE_GL=1 but: " << context##_why;             \
    GTEST_SKIP() << "no headless GL context (" << context##_why << "): skipping a GL test";  \
  }                                                                                          \
  RecordProperty("gl_context", context->Description())

constexpr int kWidth = 320, kHeight = 240;
constexpr float kFovy = 60.0f * std::numbers::pi_v<float> / 180.0f;  // radians
constexpr float kCameraZ = 5.0f;  // metres; the camera looks from (0, 0, 5) down -z
constexpr float kClear[3] = {51 / 255.0f, 102 / 255.0f, 153 / 255.0f};  // RGB, exact in 8 bits
constexpr float kPointSize = 9.0f;                                      // pixels
const Rgba kTriangleColor{255, 0, 0, 128};

// Pixel (column, row counted from the top) where the scene camera sees world point p: a pinhole
// worked out by hand, independently of Perspective() and LookAt().
Eigen::Vector2i ExpectedPixel(const Eigen::Vector3f& p) {
  const float half_height = (kCameraZ - p.z()) * std::tan(0.5f * kFovy);
  const float ndc_x = p.x() / (half_height * kWidth / kHeight), ndc_y = p.y() / half_height;
  return {static_cast<int>(std::floor(0.5f * (ndc_x + 1.0f) * kWidth)),
          static_cast<int>(std::floor(0.5f * (1.0f - ndc_y) * kHeight))};
}

Matrix4f SceneViewProjection() {
  return Perspective(kFovy, static_cast<float>(kWidth) / kHeight, 0.1f, 100.0f) *
         LookAt({0, 0, kCameraZ}, {0, 0, 0}, {0, 1, 0});
}

// BGR at (column, row) of a read-back image.
Eigen::Vector3i Bgr(const ImageU8& image, int x, int y) {
  const std::uint8_t* p = image.Row(y) + 3 * x;
  return {p[0], p[1], p[2]};
}

::testing::AssertionResult ColorNear(const ImageU8& image, int x, int y,
                                     const Eigen::Vector3i& expected_bgr, int tolerance) {
  const Eigen::Vector3i actual = Bgr(image, x, y);
  if ((actual - expected_bgr).cwiseAbs().maxCoeff() <= tolerance) {
    return ::testing::AssertionSuccess();
  }
  return ::testing::AssertionFailure()
         << "pixel (" << x << ", " << y << ") is BGR " << actual.transpose() << ", expected "
         << expected_bgr.transpose() << " +- " << tolerance;
}

// A 5x3 BGR image (odd width: 15-byte rows) and a 3x3 grey one (3-byte rows).
ImageU8 ColorImage() {
  ImageU8 image{5, 3, 3, {}};
  for (int y = 0; y < 3; ++y) {
    for (int x = 0; x < 5; ++x) {
      image.data.insert(image.data.end(), {static_cast<std::uint8_t>(40 * x + 10),
                                           static_cast<std::uint8_t>(60 * y + 20), 200});
    }
  }
  return image;
}
ImageU8 GreyImage() {
  ImageU8 image{3, 3, 1, {}};
  for (int i = 0; i < 9; ++i) image.data.push_back(static_cast<std::uint8_t>(50 + 20 * i));
  return image;
}

// Scene points: opaque markers on z = 0, one inside the translucent triangle's footprint behind
// it (z = 0) and one in front of it (z = 2).
const std::vector<Eigen::Vector3f> kPoints = {
    {0, 0, 0}, {1, 0, 0}, {-1, -0.5f, 0}, {-2.0f, 0.9f, 0}, {-1.0f, 0.55f, 2.0f}};
const std::vector<Rgba> kPointColors = {
    {255, 0, 0, 255}, {0, 255, 0, 255}, {0, 0, 255, 255}, {255, 255, 255, 255}, {0, 255, 255, 255}};
// The triangle lies on z = 1 over the upper left, covering the last two points.
const std::vector<Eigen::Vector3f> kTriangle = {{-3, 0.3f, 1}, {-0.5f, 0.3f, 1}, {-3, 2.2f, 1}};
const std::vector<Eigen::Vector3f> kLine = {{-2, -1, 0}, {2, -1, 0}};

// Draws the scene into `target` and reads it back. `cloud_points` adds that many random points
// far behind everything (for comparing backends on busier content).
ImageU8 RenderScene(Framebuffer* target, int cloud_points,
                    std::optional<PointDrawing> drawing = std::nullopt) {
  target->Resize(kWidth, kHeight);
  target->Clear(kClear[0], kClear[1], kClear[2], 1.0f);
  ImageTexture color_image, grey_image;
  color_image.Upload(ColorImage(), /*linear_filtering=*/false);
  grey_image.Upload(GreyImage(), /*linear_filtering=*/false);
  color_image.Draw(0.5f, -1.0f, 1.0f, -0.5f);   // pixels [240, 320) x [180, 240)
  grey_image.Draw(-1.0f, -1.0f, -0.5f, -0.5f);  // pixels [0, 80) x [180, 240)
  const Matrix4f view_projection = SceneViewProjection();
  PointRenderer points;
  std::vector<Eigen::Vector3f> positions = kPoints;
  std::vector<Rgba> colors = kPointColors;
  std::mt19937 random(7);
  std::uniform_real_distribution<float> uniform(-1.0f, 1.0f);
  for (int i = 0; i < cloud_points; ++i) {
    positions.emplace_back(8 * uniform(random), 6 * uniform(random), -4 + 2 * uniform(random));
    colors.push_back({static_cast<std::uint8_t>(i), static_cast<std::uint8_t>(3 * i), 128, 255});
  }
  if (drawing) points.set_drawing(*drawing);
  points.Upload(positions, colors);
  points.Draw(view_projection, kPointSize);
  LineRenderer line;
  line.Upload(kLine, {{255, 0, 255, 255}, {255, 0, 255, 255}});
  line.Draw(view_projection, 1.0f);
  TriangleRenderer triangle;
  triangle.Upload(kTriangle, {kTriangleColor, kTriangleColor, kTriangleColor});
  triangle.Draw(view_projection);
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
  return target->ReadPixels();
}

// Expected 8-bit result of "over" blending of `source` (with alpha) onto `destination`.
Eigen::Vector3i Over(const Rgba& source, const Eigen::Vector3i& destination_bgr) {
  const double a = source.a / 255.0;
  const Eigen::Vector3d src(source.b, source.g, source.r);
  return (a * src + (1 - a) * destination_bgr.cast<double>()).array().round().cast<int>();
}

TEST(GfxProjection, PerspectiveAndLookAtFollowOpenGlConventions) {
  const Matrix4f view = LookAt({1, 2, 3}, {1, 2, -7}, {0, 1, 0});
  EXPECT_TRUE(
      test::MatrixNear(view * Eigen::Vector4f(1, 2, 3, 1), Eigen::Vector4f(0, 0, 0, 1), 1e-6));
  EXPECT_TRUE(
      test::MatrixNear(view * Eigen::Vector4f(1, 2, -7, 1), Eigen::Vector4f(0, 0, -10, 1), 1e-5));
  const Matrix4f projection = Perspective(kFovy, 2.0f, 0.5f, 50.0f);
  const auto ndc = [&](const Eigen::Vector3f& p) {
    const Eigen::Vector4f clip = projection * p.homogeneous();
    return Eigen::Vector3f(clip.head<3>() / clip.w());
  };
  EXPECT_NEAR(ndc({0, 0, -0.5f}).z(), -1.0f, 1e-5);  // near plane
  EXPECT_NEAR(ndc({0, 0, -50.0f}).z(), 1.0f, 1e-4);  // far plane
  // The top edge of the view at distance d is d tan(fovy / 2); the right edge twice that.
  const float edge = 4.0f * std::tan(0.5f * kFovy);
  EXPECT_TRUE(
      test::MatrixNear(ndc({2 * edge, edge, -4.0f}).head<2>(), Eigen::Vector2f(1, 1), 1e-5));
}

TEST(GfxRender, KnownSceneHasExpectedPixels) {
  CALIBENCH_REQUIRE_GL_CONTEXT(context, HeadlessBackend::kEgl);
  Framebuffer target;
  // Both ways of drawing points: GL's own, and the software splat that software GL gets.
  for (const PointDrawing drawing : {PointDrawing::kGlPoints, PointDrawing::kSoftwareSplat}) {
    SCOPED_TRACE(drawing == PointDrawing::kGlPoints ? "GL_POINTS" : "software splat");
    const ImageU8 image = RenderScene(&target, 0, drawing);
    ASSERT_EQ(image.width, kWidth);
    ASSERT_EQ(image.height, kHeight);
    const Eigen::Vector3i background(153, 102, 51);
    EXPECT_TRUE(ColorNear(image, 160, 20, background, 0));
    // Opaque round points at their hand-computed pixels; the sprite's corner is cut off.
    for (size_t i = 0; i < 3; ++i) {
      const Eigen::Vector2i at = ExpectedPixel(kPoints[i]);
      const Rgba& c = kPointColors[i];
      EXPECT_TRUE(ColorNear(image, at.x(), at.y(), {c.b, c.g, c.r}, 0)) << "point " << i;
      EXPECT_TRUE(ColorNear(image, at.x() + 3, at.y(), {c.b, c.g, c.r}, 0)) << "point " << i;
      EXPECT_TRUE(ColorNear(image, at.x() + 4, at.y() + 4, background, 0)) << "point " << i;
    }
    // The line's row, found within one pixel of the projection (rasterization rules differ).
    const Eigen::Vector2i line_at = ExpectedPixel({0, -1, 0});
    int magenta_rows = 0;
    for (int dy = -1; dy <= 1; ++dy) {
      magenta_rows += ColorNear(image, line_at.x(), line_at.y() + dy, {255, 0, 255}, 0) ? 1 : 0;
    }
    EXPECT_GE(magenta_rows, 1);
    EXPECT_TRUE(ColorNear(image, line_at.x(), line_at.y() + 4, background, 0));
    // The translucent triangle blends over the background and over the point behind it (depth
    // test passes), but not over the point in front of it (depth test fails).
    const Eigen::Vector2i inside = ExpectedPixel({-2.2f, 0.9f, 1.0f});
    EXPECT_TRUE(ColorNear(image, inside.x(), inside.y(), Over(kTriangleColor, background), 2));
    const Eigen::Vector2i behind = ExpectedPixel(kPoints[3]);
    EXPECT_TRUE(ColorNear(image, behind.x(), behind.y(), Over(kTriangleColor, {255, 255, 255}), 2));
    const Eigen::Vector2i in_front = ExpectedPixel(kPoints[4]);
    EXPECT_TRUE(ColorNear(image, in_front.x(), in_front.y(), {255, 255, 0}, 0));
    // Image texels (nearest filtering): the BGR image's texel (x, y) covers 16x20 pixels from
    // (240, 180), the grey one's 80/3 x 20 pixels from (0, 180).
    const ImageU8 color = ColorImage(), grey = GreyImage();
    for (int y = 0; y < 3; ++y) {
      for (int x = 0; x < 5; ++x) {
        EXPECT_TRUE(ColorNear(image, 248 + 16 * x, 190 + 20 * y, Bgr(color, x, y), 0));
      }
      for (int x = 0; x < 3; ++x) {
        const int g = grey.Row(y)[x];
        EXPECT_TRUE(ColorNear(image, (80 * x + 40) / 3, 190 + 20 * y, {g, g, g}, 0));
      }
    }
  }
}

// The same scene as named layers (gfx::SceneLayers, what both workbenches' 3D views draw): the
// same pixels with every layer shown; a hidden layer leaves the background (or what is behind)
// where it was, and showing it again brings it back.
TEST(GfxSceneLayers, DrawsTheSceneAndHidesALayerByName) {
  CALIBENCH_REQUIRE_GL_CONTEXT(context, HeadlessBackend::kEgl);
  Framebuffer target;
  const ImageU8 reference = RenderScene(&target, 0, PointDrawing::kGlPoints);
  PointRenderer points;
  points.set_drawing(PointDrawing::kGlPoints);
  points.Upload(kPoints, kPointColors);
  SceneLayers layers;
  auto fill = [&] {
    layers.Clear();
    SceneLayers::Layer& cloud = layers["points"];
    cloud.points = &points;
    cloud.point_size_px = kPointSize;
    layers["line"].lines.Add(kLine[0].cast<double>(), kLine[1].cast<double>(), {255, 0, 255, 255});
    layers["triangle"].triangles.vertices = kTriangle;
    layers["triangle"].triangles.colors = {kTriangleColor, kTriangleColor, kTriangleColor};
  };
  auto draw = [&] {
    target.Resize(kWidth, kHeight);
    target.Clear(kClear[0], kClear[1], kClear[2], 1.0f);
    ImageTexture color_image, grey_image;  // as RenderScene draws them, under the layers
    color_image.Upload(ColorImage(), false);
    grey_image.Upload(GreyImage(), false);
    color_image.Draw(0.5f, -1.0f, 1.0f, -0.5f);
    grey_image.Draw(-1.0f, -1.0f, -0.5f, -0.5f);
    fill();
    layers.Draw(SceneViewProjection());
    return target.ReadPixels();
  };
  const ImageU8 all = draw();
  EXPECT_EQ(all.data, reference.data);
  const Eigen::Vector3i background(153, 102, 51);
  const Eigen::Vector2i inside = ExpectedPixel({-2.2f, 0.9f, 1.0f});
  const Eigen::Vector2i line_at = ExpectedPixel({0, -1, 0});
  layers.SetVisible("triangle", false);
  layers.SetVisible("line", false);
  const ImageU8 hidden = draw();
  EXPECT_TRUE(ColorNear(hidden, inside.x(), inside.y(), background, 0));
  for (int dy = -1; dy <= 1; ++dy)
    EXPECT_FALSE(ColorNear(hidden, line_at.x(), line_at.y() + dy, {255, 0, 255}, 0));
  const Eigen::Vector2i first_point = ExpectedPixel(kPoints[0]);
  EXPECT_TRUE(ColorNear(hidden, first_point.x(), first_point.y(),
                        {kPointColors[0].b, kPointColors[0].g, kPointColors[0].r}, 0));
  EXPECT_NE(layers.VisibilityKey(), 0u);
  layers.SetVisible("triangle", true);
  layers.SetVisible("line", true);
  EXPECT_EQ(draw().data, reference.data);
}

// A dense cloud drawn as GL_POINTS or splatted in software (point_splat.h) into a viewport that
// may be offset in the target: a line grid drawn before it cuts through it, a translucent
// triangle after it covers part of it. Every point also appears a second time, at the same
// position in another colour (a depth tie: the later one must win), and some lie outside the
// view or behind the camera. With `cloud` false, the same picture without the points.
ImageU8 RenderCloud(Framebuffer* target, PointDrawing drawing, float point_size_px, int viewport_x,
                    bool cloud = true) {
  target->Resize(kWidth, kHeight);
  target->Clear(kClear[0], kClear[1], kClear[2], 1.0f);
  if (viewport_x > 0) glViewport(viewport_x, 7, kWidth - viewport_x - 5, kHeight - 20);
  const Matrix4f view_projection = SceneViewProjection();
  LineBatch grid;
  for (int k = -4; k <= 4; ++k) {
    grid.Add({k * 1.0, -3, -3}, {k * 1.0, 3, -1}, {255, 0, 255, 255});
    grid.Add({-4, k * 0.75, -1}, {4, k * 0.75, -5}, {255, 255, 0, 255});
  }
  LineRenderer lines;
  lines.Upload(grid.vertices, grid.colors);
  lines.Draw(view_projection);
  if (cloud) {
    std::vector<Eigen::Vector3f> positions;
    std::vector<Rgba> colors;
    std::mt19937 random(11);
    std::uniform_real_distribution<float> uniform(-1.0f, 1.0f);
    for (int i = 0; i < 15000; ++i) {
      // x, y beyond the view's edges at that depth; z from in front of the camera to behind it.
      const Eigen::Vector3f p(5 * uniform(random), 4 * uniform(random),
                              -1.0f + 6.5f * uniform(random));
      for (int copy = 0; copy < 2; ++copy) {
        positions.push_back(p);
        colors.push_back({static_cast<std::uint8_t>(i),
                          static_cast<std::uint8_t>(7 * i + 90 * copy),
                          static_cast<std::uint8_t>(200 - 150 * copy), 255});
      }
    }
    PointRenderer points;
    points.set_drawing(drawing);
    points.Upload(positions, colors);
    points.Draw(view_projection, point_size_px);
  }
  TriangleRenderer triangle;
  triangle.Upload(kTriangle, {kTriangleColor, kTriangleColor, kTriangleColor});
  triangle.Draw(view_projection);
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
  return target->ReadPixels();
}

int DifferingPixels(const ImageU8& a, const ImageU8& b) {
  int differing = 0;
  for (size_t i = 0; i < a.data.size(); i += 3)
    differing +=
        a.data[i] != b.data[i] || a.data[i + 1] != b.data[i + 1] || a.data[i + 2] != b.data[i + 2];
  return differing;
}

// The splat's rules on hand-placed points, without GL: identity view-projection, so positions
// are normalized device coordinates; a 4 x 4 viewport, 2 px points.
TEST(GfxPointSplat, FollowsGlPointRules) {
  const Rgba red{255, 0, 0, 255}, green{0, 255, 0, 255}, blue{0, 0, 255, 255};
  const auto splat = [](const std::vector<Eigen::Vector3f>& positions,
                        const std::vector<Rgba>& colors, float size_px) {
    PointSplat out;
    SplatPoints(positions, colors, Matrix4f::Identity(), size_px, 4, 4, &out);
    return out;
  };
  const auto covered = [](const PointSplat& s) {
    std::vector<int> pixels;
    for (int i = 0; i < s.width * s.height; ++i)
      if (s.depth[i] != PointSplat::kEmpty) pixels.push_back(i);
    return pixels;
  };
  // A point at the viewport's centre (window 2, 2) covers the four pixels around it, at window
  // depth 0.5 as 24 bits.
  PointSplat s = splat({{0, 0, 0}}, {red}, 2.0f);
  EXPECT_EQ(covered(s), (std::vector<int>{5, 6, 9, 10}));
  EXPECT_EQ(s.depth[5], 8388607u);  // 0.5 * (2^24 - 1), truncated
  EXPECT_EQ(s.color[10].r, 255);
  // A 3 px point centred on pixel (1, 1)'s centre (window 1.5, 1.5 = NDC -0.25): its square
  // holds 3 x 3 pixel centres and its disc, radius 1.5, keeps them all (corners 1.41 away).
  EXPECT_EQ(covered(splat({{-0.25f, -0.25f, 0}}, {red}, 3.0f)).size(), 9u);
  // 4 px centred on (2, 2): 16 centres in the square, the four corners (distance 2.12 > 2) cut.
  EXPECT_EQ(covered(splat({{0, 0, 0}}, {red}, 4.0f)).size(), 12u);
  // Depth: the nearer point wins whatever the order; at equal depth the later one (GL_LEQUAL).
  s = splat({{0, 0, 0.2f}, {0, 0, -0.2f}, {0, 0, 0.1f}}, {red, green, blue}, 2.0f);
  EXPECT_EQ(s.color[5].g, 255);
  s = splat({{0, 0, 0}, {0, 0, 0}}, {red, blue}, 2.0f);
  EXPECT_EQ(s.color[5].b, 255);
  // Outside the clip volume by its centre: dropped, although its disc would reach into the view
  // (x = 1.1 is window 4.2, the disc spans 3.2 to 5.2); beyond the far or the near plane; behind
  // the eye (w < 0 through a perspective matrix).
  EXPECT_TRUE(covered(splat({{1.1f, 0, 0}}, {red}, 2.0f)).empty());
  EXPECT_TRUE(covered(splat({{0, 0, 1.5f}}, {red}, 2.0f)).empty());
  EXPECT_TRUE(covered(splat({{0, 0, -1.5f}}, {red}, 2.0f)).empty());
  PointSplat behind;
  SplatPoints({{0, 0, 1}}, {red}, Perspective(1.0f, 1.0f, 0.1f, 10.0f), 2.0f, 4, 4, &behind);
  EXPECT_TRUE(covered(behind).empty());
  // Points that are not numbers (a cloud's missing returns) or infinite draw nothing.
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  EXPECT_TRUE(
      covered(splat({{nan, 0, 0}, {0, inf, 0}, {0, 0, -inf}}, {red, red, red}, 2.0f)).empty());
  // An oblique view mixes every coordinate into clip x, y, z and w: (-inf, 0, 0) gives w = +inf
  // and |x| = inf, which passes "|x| <= w"; only the finiteness check keeps its NaN window
  // coordinates from an int cast (undefined behaviour, which on x86 happens to draw nothing).
  const Matrix4f oblique =
      Perspective(1.0f, 1.0f, 0.1f, 10.0f) * LookAt({3, 2, 5}, {0, 0, 0}, {0, 1, 0});
  SplatPoints({{0, 0, -inf}, {inf, 0, -1}, {-inf, 0, 0}}, {red, red, red}, oblique, 2.0f, 4, 4,
              &behind);
  EXPECT_TRUE(covered(behind).empty());
  // A 2 px point exactly on pixel (1, 1)'s centre (window 1.5, 1.5): the square's left and
  // bottom edges are in, its right and top edges out, the disc's rim in: three pixels, as
  // llvmpipe draws them.
  EXPECT_EQ(covered(splat({{-0.25f, -0.25f, 0}}, {red}, 2.0f)), (std::vector<int>{1, 4, 5}));
  // Sizes are clamped to [1, 255] px as GL clamps them; one that is not a number draws 1 px.
  EXPECT_EQ(covered(splat({{-0.25f, -0.25f, 0}}, {red}, 0.0f)), (std::vector<int>{5}));
  EXPECT_EQ(covered(splat({{-0.25f, -0.25f, 0}}, {red}, nan)), (std::vector<int>{5}));
  EXPECT_EQ(covered(splat({{0, 0, 0}}, {red}, 1e9f)).size(), 16u);
  // On the viewport's edge (window x = 4): only the half inside is drawn.
  EXPECT_EQ(covered(splat({{1.0f, 0, 0}}, {red}, 2.0f)), (std::vector<int>{7, 11}));
}

TEST(GfxPointSplat, DrawsThePicturesGlPointsDraw) {
  CALIBENCH_REQUIRE_GL_CONTEXT(context, HeadlessBackend::kAuto);
  // The splat follows llvmpipe's rules (depth truncated to 24 bits, points clipped by their
  // centre), which GPUs need not share; they draw GL_POINTS anyway.
  if (!IsSoftwareRenderer()) GTEST_SKIP() << "the splat is compared with software GL only";
  Framebuffer target;
  for (const float size : {1.0f, 2.0f, 3.5f, 9.0f}) {
    for (const int viewport_x : {0, 13}) {
      SCOPED_TRACE("point size " + std::to_string(size) + " px, viewport x " +
                   std::to_string(viewport_x));
      const ImageU8 gl = RenderCloud(&target, PointDrawing::kGlPoints, size, viewport_x);
      const ImageU8 splat = RenderCloud(&target, PointDrawing::kSoftwareSplat, size, viewport_x);
      const ImageU8 empty = RenderCloud(&target, PointDrawing::kGlPoints, size, viewport_x, false);
      // The points change a good part of the picture, so that agreeing means something ...
      const int drawn = DifferingPixels(gl, empty);
      EXPECT_GT(drawn, kWidth * kHeight / 16);
      // ... and both ways agree but for rounding at the edges of a disc or of the view, and
      // depth ties between a line and a point: at most 0.1 % of the pixels.
      const int differing = DifferingPixels(gl, splat);
      EXPECT_LE(differing, kWidth * kHeight / 1000) << drawn << " pixels show points";
      RecordProperty("differing_size_" + std::to_string(static_cast<int>(size * 10)) + "_x" +
                         std::to_string(viewport_x),
                     differing);
    }
  }
}

TEST(GfxRender, EglAndOsMesaDrawTheSameScene) {
  ImageU8 egl_image, osmesa_image;
  std::string egl_description;
  {
    CALIBENCH_REQUIRE_GL_CONTEXT(egl, HeadlessBackend::kEgl);
    Framebuffer target;
    egl_image = RenderScene(&target, 1500);
    egl_description = egl->Description();
  }
  CALIBENCH_REQUIRE_GL_CONTEXT(osmesa, HeadlessBackend::kOsMesa);
  Framebuffer target;
  osmesa_image = RenderScene(&target, 1500);
  // Two rasterizers may round blending and point coverage differently, and an edge pixel may
  // fall in or out; a few such pixels are fine, many are not. (On Mesa llvmpipe both backends
  // give identical images.)
  constexpr int kChannelTolerance = 3;
  constexpr double kMaxDifferingFraction = 0.002;
  ImageU8 diff{kWidth, kHeight, 3, std::vector<std::uint8_t>(kWidth * kHeight * 3, 0)};
  int differing = 0;
  for (size_t i = 0; i < egl_image.data.size(); i += 3) {
    int worst = 0;
    for (int c = 0; c < 3; ++c) {
      worst = std::max(worst, std::abs(egl_image.data[i + c] - osmesa_image.data[i + c]));
    }
    if (worst > kChannelTolerance) {
      ++differing;
      diff.data[i + 2] = 255;
    }
  }
  const int allowed = static_cast<int>(kMaxDifferingFraction * kWidth * kHeight);
  if (differing > allowed) {
    const auto dir = test::TempDir("gfx_egl_vs_osmesa");
    SaveImage(dir / "egl.png", egl_image);
    SaveImage(dir / "osmesa.png", osmesa_image);
    SaveImage(dir / "diff.png", diff);
    ADD_FAILURE() << differing << " pixels differ by more than " << kChannelTolerance
                  << " (at most " << allowed << " allowed) between " << egl_description << " and "
                  << osmesa->Description() << "; images in " << dir;
  }
}

// EGL (through glvnd) and OSMesa share Mesa's GL dispatch: MakeCurrent must really switch it,
// even for an EGL context that EGL itself still considers current.
TEST(GfxContext, MakeCurrentSwitchesBetweenBackends) {
  CALIBENCH_REQUIRE_GL_CONTEXT(egl, HeadlessBackend::kEgl);
  auto egl_target = std::make_unique<Framebuffer>();
  egl_target->Resize(8, 8);
  egl_target->Clear(0, 1, 0, 1);
  CALIBENCH_REQUIRE_GL_CONTEXT(osmesa, HeadlessBackend::kOsMesa);
  auto osmesa_target = std::make_unique<Framebuffer>();
  osmesa_target->Resize(8, 8);
  osmesa_target->Clear(1, 0, 0, 1);
  egl->MakeCurrent();
  EXPECT_TRUE(ColorNear(egl_target->ReadPixels(), 4, 4, {0, 255, 0}, 0));
  osmesa->MakeCurrent();
  EXPECT_TRUE(ColorNear(osmesa_target->ReadPixels(), 4, 4, {0, 0, 255}, 0));
  // GL objects die with their own context current.
  osmesa_target.reset();
  egl->MakeCurrent();
  egl_target.reset();
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

TEST(GfxFramebuffer, ReadPixelsReturnsTopRowFirst) {
  CALIBENCH_REQUIRE_GL_CONTEXT(context, HeadlessBackend::kAuto);
  Framebuffer target;
  target.Resize(kWidth, kHeight);
  target.Clear(0, 0, 0, 1);
  PointRenderer point;
  point.Upload({{0.0f, 0.9f, 0.0f}}, {{255, 0, 0, 255}});
  point.Draw(Matrix4f::Identity(), 5.0f);  // NDC y = 0.9: near the top edge of the target
  const ImageU8 image = target.ReadPixels();
  const int top_row = static_cast<int>(0.5 * (1.0 - 0.9) * kHeight);  // 12
  EXPECT_TRUE(ColorNear(image, kWidth / 2, top_row, {0, 0, 255}, 0));
  EXPECT_TRUE(ColorNear(image, kWidth / 2, kHeight - 1 - top_row, {0, 0, 0}, 0));
}

TEST(GfxFramebuffer, ResizeReallocatesOnlyOnChange) {
  CALIBENCH_REQUIRE_GL_CONTEXT(context, HeadlessBackend::kAuto);
  Framebuffer target;
  target.Resize(kWidth, kHeight);
  const std::uint32_t texture = target.color_texture();
  target.Resize(kWidth, kHeight);
  EXPECT_EQ(target.color_texture(), texture);
  target.Resize(65, 33);  // odd width: read-back rows of 195 bytes
  EXPECT_EQ(target.width(), 65);
  EXPECT_EQ(target.height(), 33);
  target.Clear(1.0f, 0.0f, 0.0f, 1.0f);
  PointRenderer point;
  point.Upload({{0, 0, 0}}, {{0, 255, 0, 255}});
  point.Draw(Matrix4f::Identity(), 3.0f);
  const ImageU8 image = target.ReadPixels();
  ASSERT_EQ(image.width, 65);
  ASSERT_EQ(image.height, 33);
  ASSERT_EQ(image.data.size(), 65u * 33u * 3u);
  EXPECT_TRUE(ColorNear(image, 64, 32, {0, 0, 255}, 0));
  EXPECT_TRUE(ColorNear(image, 32, 16, {0, 255, 0}, 0));
  EXPECT_THROW(target.Resize(0, 10), std::invalid_argument);
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

TEST(GfxRenderers, RejectMismatchedUploads) {
  CALIBENCH_REQUIRE_GL_CONTEXT(context, HeadlessBackend::kAuto);
  LineRenderer lines;
  EXPECT_THROW(lines.Upload({{0, 0, 0}}, {{}}), std::invalid_argument);  // odd vertex count
  TriangleRenderer triangles;
  EXPECT_THROW(triangles.Upload({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{}}), std::invalid_argument);
  ImageTexture texture;
  EXPECT_THROW(texture.Upload(ImageU8{2, 2, 4, std::vector<std::uint8_t>(16)}),
               std::invalid_argument);
}

TEST(GfxContext, ParsesBackendNames) {
  HeadlessBackend backend = HeadlessBackend::kAuto;
  EXPECT_TRUE(ParseHeadlessBackend("osmesa", &backend));
  EXPECT_EQ(backend, HeadlessBackend::kOsMesa);
  EXPECT_TRUE(ParseHeadlessBackend("egl", &backend));
  EXPECT_EQ(backend, HeadlessBackend::kEgl);
  EXPECT_TRUE(ParseHeadlessBackend("auto", &backend));
  EXPECT_EQ(backend, HeadlessBackend::kAuto);
  EXPECT_FALSE(ParseHeadlessBackend("EGL", &backend));
}

}  // namespace
}  // namespace calibench::gfx
