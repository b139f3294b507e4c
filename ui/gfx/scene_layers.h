// A 3D view's scene as named layers drawn in order (the model: iridescence's named drawables in
// guik): each layer holds its lines, its translucent triangles and, optionally, a point cloud
// uploaded elsewhere (kept on the GPU across frames). A view refills the layers when what they
// show changes; the user shows or hides them by name (LayerToggles in ui/widgets). Both
// workbenches' 3D views are built from it, so that the ghost board, the frustums and the rays
// are layers like the points and the boards, not special cases.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "ui/gfx/renderers.h"

namespace calibench::gfx {

class SceneLayers {
 public:
  struct Layer {
    std::string name;
    LineBatch lines;
    TriangleBatch triangles;                // translucent: drawn after the points
    const PointRenderer* points = nullptr;  // not owned; uploaded by the view
    float point_size_px = 2.0f;
    float line_width_px = 1.0f;
    bool visible = true;
  };

  // The layer `name`, added at the end of the drawing order on first use.
  Layer& operator[](const std::string& name);
  // Empties every layer's lines, triangles and points; order and visibility stay (the user's).
  void Clear();
  void SetVisible(const std::string& name, bool visible);
  const std::vector<Layer>& layers() const { return layers_; }
  // Which layers are visible, as bits in drawing order: part of a view's redraw key.
  std::uint64_t VisibilityKey() const;
  // Into the bound target, layer by layer in order: lines, then points; the triangles of every
  // visible layer last (translucent ones blend over everything opaque).
  void Draw(const Matrix4f& view_projection);

 private:
  std::vector<Layer> layers_;
  LineRenderer lines_;  // reused for every layer: uploaded, then drawn at once
  TriangleRenderer triangles_;
};

}  // namespace calibench::gfx
