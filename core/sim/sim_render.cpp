// The printed board (core/target/board_print.h) in a supersampled camera rendering.
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "core/sim/sim.h"

namespace calibench {
namespace {

constexpr double kInkGrey = 20.0;     // rendered grey of black ink (0..255)
constexpr double kPaperGrey = 235.0;  // white paper, below 255 so that noise does not clip
// Bearings are unprojected exactly on a grid of this pitch (pixels) and interpolated in between:
// the interpolation error is below 0.005 px for the cameras we simulate (measured), and Newton per
// sample would cost ~0.5 us.
constexpr int kNodeStep = 4;

struct PixelBox {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;  // [x0, x1) × [y0, y1)
  int Width() const { return x1 - x0; }
  int Height() const { return y1 - y0; }
};

// The pixels whose rays can hit the sheet: the bounding box of densely sampled sheet edges (edges
// curve under distortion). The whole image when part of the sheet cannot be projected.
std::optional<PixelBox> SheetPixelBox(const CameraModel& camera, const BoardPrint& print,
                                      const Pose& cam_from_board) {
  const double hw = 0.5 * print.board().SheetWidth(), hh = 0.5 * print.board().SheetHeight();
  const Vec2 corners[5] = {{-hw, -hh}, {hw, -hh}, {hw, hh}, {-hw, hh}, {-hw, -hh}};
  constexpr int kSamplesPerEdge = 64;
  double min_x = 1e300, min_y = 1e300, max_x = -1e300, max_y = -1e300;
  for (int e = 0; e < 4; ++e) {
    for (int k = 0; k < kSamplesPerEdge; ++k) {
      const Vec2 xy = corners[e] + (corners[e + 1] - corners[e]) * k / kSamplesPerEdge;
      const auto pixel = camera.Project(cam_from_board * Vec3(xy.x(), xy.y(), 0.0));
      if (!pixel) return PixelBox{0, 0, camera.width, camera.height};
      min_x = std::min(min_x, pixel->x()), max_x = std::max(max_x, pixel->x());
      min_y = std::min(min_y, pixel->y()), max_y = std::max(max_y, pixel->y());
    }
  }
  constexpr double kPad = 2.0;  // pixels: the curved edge between samples, and the pixel extent
  PixelBox box;
  box.x0 = std::max(0, static_cast<int>(std::floor(min_x - kPad)));
  box.y0 = std::max(0, static_cast<int>(std::floor(min_y - kPad)));
  box.x1 = std::min(camera.width, static_cast<int>(std::ceil(max_x + kPad)) + 1);
  box.y1 = std::min(camera.height, static_cast<int>(std::ceil(max_y + kPad)) + 1);
  if (box.x0 >= box.x1 || box.y0 >= box.y1) return std::nullopt;
  return box;
}

// Homogeneous board coordinates q = [r1 r2 t]^-1 · bearing of the pixels in a box: the ray hits
// the board plane at (q0/q2, q1/q2) in front of the camera iff q2 > 0. Exact on a node grid of
// pitch kNodeStep, bilinear in between (q is linear in the bearing).
class BoardRayGrid {
 public:
  BoardRayGrid(const CameraModel& camera, const Mat3& plane_inverse, const PixelBox& box)
      : camera_(camera), plane_inverse_(plane_inverse), box_(box) {
    nodes_x_ = (box.Width() + kNodeStep - 1) / kNodeStep + 1;
    nodes_y_ = (box.Height() + kNodeStep - 1) / kNodeStep + 1;
    nodes_.resize(static_cast<size_t>(nodes_x_) * nodes_y_);
    for (int b = 0; b < nodes_y_; ++b) {
      for (int a = 0; a < nodes_x_; ++a) {
        nodes_[b * nodes_x_ + a] =
            Exact(box.x0 - 0.5 + a * kNodeStep, box.y0 - 0.5 + b * kNodeStep);
      }
    }
  }

  // rel = pixel position minus the box's top-left pixel corner (x0 - 0.5, y0 - 0.5).
  Vec3 At(double rel_x, double rel_y) const {
    const double fx = rel_x / kNodeStep, fy = rel_y / kNodeStep;
    const int a = std::clamp(static_cast<int>(fx), 0, nodes_x_ - 2);
    const int b = std::clamp(static_cast<int>(fy), 0, nodes_y_ - 2);
    const double wx = fx - a, wy = fy - b;
    const Vec3* n = &nodes_[b * nodes_x_ + a];
    const Vec3& q00 = n[0];
    const Vec3& q10 = n[1];
    const Vec3& q01 = n[nodes_x_];
    const Vec3& q11 = n[nodes_x_ + 1];
    if (!q00.allFinite() || !q10.allFinite() || !q01.allFinite() || !q11.allFinite()) {
      return Exact(box_.x0 - 0.5 + rel_x, box_.y0 - 0.5 + rel_y);
    }
    return (1 - wy) * ((1 - wx) * q00 + wx * q10) + wy * ((1 - wx) * q01 + wx * q11);
  }

 private:
  Vec3 Exact(double px, double py) const {
    const auto bearing = camera_.Unproject(Vec2(px, py));
    if (!bearing) return Vec3::Constant(std::numeric_limits<double>::quiet_NaN());
    return plane_inverse_ * *bearing;
  }

  const CameraModel& camera_;
  Mat3 plane_inverse_;
  PixelBox box_;
  int nodes_x_ = 0, nodes_y_ = 0;
  std::vector<Vec3> nodes_;
};

// Grey value and a region code for the fast path: a pixel whose four corners share a code >= 0
// lies in one convex region of constant grey (a square, a margin band, a background band).
class BoardShader {
 public:
  BoardShader(const BoardPrint& print, bool front_facing, double background)
      : print_(print), front_(front_facing), background_(background) {
    const BoardSpec& board = print.board();
    half_sheet_ = Vec2(0.5 * board.SheetWidth(), 0.5 * board.SheetHeight());
    half_pattern_ = Vec2(0.5 * board.PatternWidth(), 0.5 * board.PatternHeight());
    // A square is uniform when it is black: checkerboard squares are all uniform, ChArUco white
    // squares carry markers. Probe each square's texture near its corner, inside the marker gap.
    const double s = board.square_size;
    const double inset = board.type == BoardType::kCharuco
                             ? 0.25 * std::max(s - board.marker_size, 0.02 * s)
                             : 0.5 * s;
    for (int j = 0; j < board.SquaresY(); ++j) {
      for (int i = 0; i < board.SquaresX(); ++i) {
        const Vec2 probe(i * s + inset - half_pattern_.x(), j * s + inset - half_pattern_.y());
        const bool black = print.Reflectance(probe) < 0.5;
        uniform_square_.push_back(board.type == BoardType::kCheckerboard || black);
      }
    }
  }

  double Grey(const Vec3& q) const {
    if (q.z() <= 0.0) return background_;
    const Vec2 xy(q.x() / q.z(), q.y() / q.z());
    if (!print_.InSheet(xy)) return background_;
    if (!front_) return kPaperGrey;  // the plain back of the sheet
    return kInkGrey + (kPaperGrey - kInkGrey) * print_.Reflectance(xy);
  }

  int Region(const Vec3& q) const {
    if (!(q.z() > 0.0)) return -1;
    const Vec2 xy(q.x() / q.z(), q.y() / q.z());
    const int band_sheet = Band(xy, half_sheet_);
    if (band_sheet != 4) return band_sheet;  // background bands 0..8 except 4
    if (!front_) return 4;
    const int band_pattern = Band(xy, half_pattern_);
    if (band_pattern != 4) return 10 + band_pattern;  // margin bands
    const BoardSpec& board = print_.board();
    const auto [i, j] = PatternSquareAt(board, xy);
    const int square = j * board.SquaresX() + i;
    return uniform_square_[square] ? 100 + square : -1;
  }

 private:
  // 3x3 position code of a point relative to a centred rectangle; 4 = inside.
  static int Band(const Vec2& xy, const Vec2& half) {
    const int bx = xy.x() < -half.x() ? 0 : (xy.x() > half.x() ? 2 : 1);
    const int by = xy.y() < -half.y() ? 0 : (xy.y() > half.y() ? 2 : 1);
    return by * 3 + bx;
  }

  const BoardPrint& print_;
  bool front_;
  double background_;
  Vec2 half_sheet_, half_pattern_;
  std::vector<bool> uniform_square_;
};

// Renders the box into grey (row-major, full image size).
void RenderBox(const BoardRayGrid& grid, const BoardShader& shader, const PixelBox& box,
               int image_width, int supersampling, std::vector<double>* grey) {
  const int w = box.Width();
  std::vector<int> upper(w + 1), lower(w + 1);
  auto corner_row = [&](int j, std::vector<int>* codes) {
    for (int i = 0; i <= w; ++i) (*codes)[i] = shader.Region(grid.At(i, j));
  };
  corner_row(0, &upper);
  const double inv_s = 1.0 / supersampling;
  for (int j = 0; j < box.Height(); ++j) {
    corner_row(j + 1, &lower);
    double* out = grey->data() + static_cast<size_t>(box.y0 + j) * image_width + box.x0;
    for (int i = 0; i < w; ++i) {
      const int code = upper[i];
      if (code >= 0 && upper[i + 1] == code && lower[i] == code && lower[i + 1] == code) {
        out[i] = shader.Grey(grid.At(i + 0.5, j + 0.5));
        continue;
      }
      // Sample offsets (k + 1/2)/s - 1/2 are symmetric about the pixel centre: no bias.
      double sum = 0.0;
      for (int sy = 0; sy < supersampling; ++sy) {
        for (int sx = 0; sx < supersampling; ++sx) {
          sum += shader.Grey(grid.At(i + (sx + 0.5) * inv_s, j + (sy + 0.5) * inv_s));
        }
      }
      out[i] = sum * inv_s * inv_s;
    }
    std::swap(upper, lower);
  }
}

// Gaussian noise by Box-Muller on SplitMix64: 5x faster than std::normal_distribution on
// mt19937_64, which dominated the render time of large images.
void AddGaussianNoise(double sigma, std::uint64_t seed, std::vector<double>* values) {
  std::uint64_t state = seed;
  auto next = [&state] {
    std::uint64_t z = (state += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  };
  constexpr double kTwoPow53 = 9007199254740992.0;
  for (size_t i = 0; i < values->size(); i += 2) {
    const double u1 = ((next() >> 11) + 1) / kTwoPow53;  // (0, 1]
    const double u2 = (next() >> 11) / kTwoPow53;        // [0, 1)
    const double radius = sigma * std::sqrt(-2.0 * std::log(u1));
    (*values)[i] += radius * std::cos(2.0 * M_PI * u2);
    if (i + 1 < values->size()) (*values)[i + 1] += radius * std::sin(2.0 * M_PI * u2);
  }
}

}  // namespace

ImageU8 RenderBoardImage(const CameraModel& camera, const BoardSpec& board,
                         const Pose& cam_from_board, const RenderOptions& options) {
  CALIBENCH_CHECK(camera.width > 0 && camera.height > 0);
  CALIBENCH_CHECK(options.supersampling >= 1 && options.image_noise >= 0.0);
  const BoardPrint print(board);
  std::vector<double> grey(static_cast<size_t>(camera.width) * camera.height,
                           static_cast<double>(options.background));
  Mat3 plane;  // [r1 r2 t]: board (x, y, 1) -> camera ray (Zhang's homography)
  plane << cam_from_board.linear().col(0), cam_from_board.linear().col(1),
      cam_from_board.translation();
  const bool seen_edge_on = std::abs(plane.determinant()) < 1e-12;
  const auto box = SheetPixelBox(camera, print, cam_from_board);
  if (box && !seen_edge_on) {
    const bool front = cam_from_board.linear().col(2).dot(cam_from_board.translation()) > 0.0;
    const BoardRayGrid grid(camera, plane.inverse(), *box);
    const BoardShader shader(print, front, options.background);
    RenderBox(grid, shader, *box, camera.width, options.supersampling, &grey);
  }
  ImageU8 image;
  image.width = camera.width;
  image.height = camera.height;
  image.channels = 3;
  image.data.resize(grey.size() * 3);
  if (options.image_noise > 0.0) AddGaussianNoise(options.image_noise * 255.0, options.seed, &grey);
  for (size_t p = 0; p < grey.size(); ++p) {
    const auto v = static_cast<std::uint8_t>(std::lround(std::clamp(grey[p], 0.0, 255.0)));
    image.data[3 * p] = image.data[3 * p + 1] = image.data[3 * p + 2] = v;
  }
  return image;
}

}  // namespace calibench
