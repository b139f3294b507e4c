#include "ui/gfx/scene_layers.h"

namespace calibench::gfx {

SceneLayers::Layer& SceneLayers::operator[](const std::string& name) {
  for (Layer& layer : layers_)
    if (layer.name == name) return layer;
  layers_.push_back(Layer{name});
  return layers_.back();
}

void SceneLayers::Clear() {
  for (Layer& layer : layers_) {
    layer.lines = {};
    layer.triangles = {};
    layer.points = nullptr;
  }
}

void SceneLayers::SetVisible(const std::string& name, bool visible) {
  (*this)[name].visible = visible;
}

std::uint64_t SceneLayers::VisibilityKey() const {
  std::uint64_t key = 0;
  for (size_t i = 0; i < layers_.size() && i < 64; ++i)
    if (layers_[i].visible) key |= std::uint64_t{1} << i;
  return key;
}

void SceneLayers::Draw(const Matrix4f& view_projection) {
  for (const Layer& layer : layers_) {
    if (!layer.visible) continue;
    if (!layer.lines.vertices.empty()) {
      lines_.Upload(layer.lines.vertices, layer.lines.colors);
      lines_.Draw(view_projection, layer.line_width_px);
    }
    if (layer.points) layer.points->Draw(view_projection, layer.point_size_px);
  }
  // One upload for every visible layer's triangles.
  TriangleBatch all;
  for (const Layer& layer : layers_) {
    if (!layer.visible) continue;
    all.vertices.insert(all.vertices.end(), layer.triangles.vertices.begin(),
                        layer.triangles.vertices.end());
    all.colors.insert(all.colors.end(), layer.triangles.colors.begin(),
                      layer.triangles.colors.end());
  }
  if (all.vertices.empty()) return;
  triangles_.Upload(all.vertices, all.colors);
  triangles_.Draw(view_projection);
}

}  // namespace calibench::gfx
