#include "ui/gfx/texture_versions.h"

#include <unordered_map>

namespace calibench::gfx {
namespace {

struct Versions {
  std::uint64_t last = 0;
  std::unordered_map<std::uint32_t, std::uint64_t> of_texture;
};

Versions& TheVersions() {
  static Versions versions;
  return versions;
}

}  // namespace

void MarkTextureChanged(std::uint32_t texture) {
  Versions& versions = TheVersions();
  versions.of_texture[texture] = ++versions.last;
}

std::uint64_t TextureVersion(std::uint32_t texture) {
  const Versions& versions = TheVersions();
  const auto it = versions.of_texture.find(texture);
  return it == versions.of_texture.end() ? 0 : it->second;
}

}  // namespace calibench::gfx
