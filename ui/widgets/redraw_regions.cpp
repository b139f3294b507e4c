#include "ui/widgets/redraw_regions.h"

#include <algorithm>
#include <cstring>
#include <unordered_map>
#include <utility>

#include "ui/widgets/frame_key.h"

namespace calibench::ui {
namespace {

// More boxes than this are repainted as their union: each box costs a pass over the commands.
constexpr size_t kMaxRegions = 16;

bool Empty(const PixelBox& b) { return b.width <= 0 || b.height <= 0; }

PixelBox Intersect(const PixelBox& a, const PixelBox& b) {
  const int x0 = std::max(a.x, b.x), y0 = std::max(a.y, b.y);
  const int x1 = std::min(a.x + a.width, b.x + b.width),
            y1 = std::min(a.y + a.height, b.y + b.height);
  if (x1 <= x0 || y1 <= y0) return {};
  return {x0, y0, x1 - x0, y1 - y0};
}

PixelBox Union(const PixelBox& a, const PixelBox& b) {
  if (Empty(a)) return b;
  if (Empty(b)) return a;
  const int x0 = std::min(a.x, b.x), y0 = std::min(a.y, b.y);
  const int x1 = std::max(a.x + a.width, b.x + b.width),
            y1 = std::max(a.y + a.height, b.y + b.height);
  return {x0, y0, x1 - x0, y1 - y0};
}

// Boxes that share a pixel are replaced by their union until none do: a pixel inside two regions
// would be blended twice.
std::vector<PixelBox> Disjoint(std::vector<PixelBox> boxes) {
  std::erase_if(boxes, Empty);
  for (bool merged = true; merged;) {
    merged = false;
    for (size_t i = 0; i < boxes.size() && !merged; ++i)
      for (size_t j = i + 1; j < boxes.size() && !merged; ++j)
        if (!Empty(Intersect(boxes[i], boxes[j]))) {
          boxes[i] = Union(boxes[i], boxes[j]);
          boxes.erase(boxes.begin() + static_cast<std::ptrdiff_t>(j));
          merged = true;
        }
  }
  if (boxes.size() > kMaxRegions) {
    PixelBox all;
    for (const PixelBox& b : boxes) all = Union(all, b);
    boxes = {all};
  }
  return boxes;
}

// The ClipRect that makes the backend's scissor exactly `box` (inside the framebuffer). The
// backend truncates both the corner and the size to int, so the corner goes a quarter pixel
// inside and the far edge half a pixel out, which survives the display-scale round trip.
ImVec4 ClipRectFor(const ImDrawData& draw_data, const PixelBox& box, int fb_height) {
  const ImVec2 off = draw_data.DisplayPos, scale = draw_data.FramebufferScale;
  const float x0 = box.x + 0.25f, x1 = box.x + box.width + 0.5f;
  const float y_max = fb_height - box.y - 0.25f, y_min = y_max - box.height - 0.25f;
  return {x0 / scale.x + off.x, y_min / scale.y + off.y, x1 / scale.x + off.x,
          y_max / scale.y + off.y};
}

std::uint64_t NameHash(const char* name) {
  FrameKey key(0);
  if (name) key.Mix(name, std::strlen(name));
  return key.value();
}

template <typename T>
void MixValue(FrameKey* key, const T& value) {
  key->Mix(&value, sizeof(value));
}

}  // namespace

PixelBox WholeFramebuffer(const ImDrawData& draw_data) {
  return {0, 0, static_cast<int>(draw_data.DisplaySize.x * draw_data.FramebufferScale.x),
          static_cast<int>(draw_data.DisplaySize.y * draw_data.FramebufferScale.y)};
}

PixelBox CommandScissor(const ImDrawData& draw_data, const ImDrawCmd& command) {
  // The arithmetic of imgui_impl_opengl3.cpp (ImGui_ImplOpenGL3_RenderDrawData), to the cast.
  const PixelBox framebuffer = WholeFramebuffer(draw_data);
  const ImVec2 off = draw_data.DisplayPos, scale = draw_data.FramebufferScale;
  const ImVec2 clip_min((command.ClipRect.x - off.x) * scale.x,
                        (command.ClipRect.y - off.y) * scale.y);
  const ImVec2 clip_max((command.ClipRect.z - off.x) * scale.x,
                        (command.ClipRect.w - off.y) * scale.y);
  if (clip_max.x <= clip_min.x || clip_max.y <= clip_min.y) return {};
  const PixelBox scissor{
      static_cast<int>(clip_min.x), static_cast<int>(framebuffer.height - clip_max.y),
      static_cast<int>(clip_max.x - clip_min.x), static_cast<int>(clip_max.y - clip_min.y)};
  return Intersect(scissor, framebuffer);
}

RedrawRegions::RedrawRegions(TextureVersionFn texture_version)
    : texture_version_(std::move(texture_version)) {}

std::vector<RedrawRegions::ListPrint> RedrawRegions::Print(const ImDrawData& draw_data) const {
  std::vector<ListPrint> lists(static_cast<size_t>(draw_data.CmdListsCount));
  for (int n = 0; n < draw_data.CmdListsCount; ++n) {
    const ImDrawList& list = *draw_data.CmdLists[n];
    ListPrint& print = lists[static_cast<size_t>(n)];
    print.name = NameHash(list._OwnerName);
    print.commands.reserve(static_cast<size_t>(list.CmdBuffer.Size));
    for (const ImDrawCmd& command : list.CmdBuffer) {
      CommandPrint& out = print.commands.emplace_back();
      out.box = CommandScissor(draw_data, command);
      print.bounds = Union(print.bounds, out.box);
      FrameKey key(0);
      MixValue(&key, out.box);
      MixValue(&key, command.TextureId);
      MixValue(&key, texture_version_(command.TextureId));
      MixValue(&key, command.UserCallback);
      MixValue(&key, command.ElemCount);
      if (command.ElemCount > 0) {
        // The indices, and the vertices they reach.
        const ImDrawIdx* indices = list.IdxBuffer.Data + command.IdxOffset;
        key.Mix(indices, command.ElemCount * sizeof(ImDrawIdx));
        const auto [lo, hi] = std::minmax_element(indices, indices + command.ElemCount);
        key.Mix(list.VtxBuffer.Data + command.VtxOffset + *lo,
                (static_cast<size_t>(*hi) - *lo + 1) * sizeof(ImDrawVert));
      }
      out.hash = key.value();
    }
  }
  return lists;
}

// The boxes whose pixels differ between the last frame and `current`; the whole framebuffer when
// the windows' stacking changed or a window's name is not unique.
std::vector<PixelBox> RedrawRegions::Changed(const std::vector<ListPrint>& current) const {
  const std::vector<PixelBox> everything = {previous_framebuffer_};
  std::unordered_map<std::uint64_t, size_t> previous_of;
  for (size_t i = 0; i < previous_.size(); ++i)
    if (!previous_of.emplace(previous_[i].name, i).second) return everything;
  std::unordered_map<std::uint64_t, size_t> current_names;
  std::vector<bool> still_there(previous_.size(), false);
  std::vector<PixelBox> changed;
  size_t last_matched = 0;
  bool first_match = true;
  for (const ListPrint& list : current) {
    if (!current_names.emplace(list.name, 0).second) return everything;
    const auto it = previous_of.find(list.name);
    if (it == previous_of.end()) {  // a window appeared
      changed.push_back(list.bounds);
      continue;
    }
    // A window that moved in the stacking order changes what covers what.
    if (!first_match && it->second < last_matched) return everything;
    first_match = false;
    last_matched = it->second;
    still_there[it->second] = true;
    const ListPrint& before = previous_[it->second];
    if (before.commands.size() != list.commands.size()) {
      changed.push_back(before.bounds);
      changed.push_back(list.bounds);
      continue;
    }
    for (size_t k = 0; k < list.commands.size(); ++k)
      if (before.commands[k].hash != list.commands[k].hash) {
        changed.push_back(before.commands[k].box);
        changed.push_back(list.commands[k].box);
      }
  }
  for (size_t i = 0; i < previous_.size(); ++i)  // windows that closed
    if (!still_there[i]) changed.push_back(previous_[i].bounds);
  return changed;
}

std::vector<PixelBox> RedrawRegions::Update(const ImDrawData& draw_data) {
  std::vector<ListPrint> current = Print(draw_data);
  const PixelBox framebuffer = WholeFramebuffer(draw_data);
  std::vector<PixelBox> boxes;
  if (!have_previous_ || !(framebuffer == previous_framebuffer_))
    boxes = {framebuffer};
  else
    boxes = Changed(current);
  previous_ = std::move(current);
  previous_framebuffer_ = framebuffer;
  have_previous_ = true;
  for (PixelBox& box : boxes) box = Intersect(box, framebuffer);
  return Disjoint(std::move(boxes));
}

RegionRedraw::RegionRedraw() : composed_(ImGui::GetDrawListSharedData()) {}

const ImDrawData* RegionRedraw::Compose(const ImDrawData& draw_data,
                                        const std::vector<PixelBox>& regions) {
  for (int n = 0; n < draw_data.CmdListsCount; ++n)
    for (const ImDrawCmd& command : draw_data.CmdLists[n]->CmdBuffer)
      if (command.UserCallback) return nullptr;
  composed_.CmdBuffer.resize(0);
  composed_.VtxBuffer.resize(0);
  composed_.IdxBuffer.resize(0);
  const int fb_height = WholeFramebuffer(draw_data).height;
  // The vertices and indices of every list with something in a region, once.
  struct Placed {
    const ImDrawList* list;
    unsigned vtx_base, idx_base;
  };
  std::vector<Placed> placed;
  for (int n = 0; n < draw_data.CmdListsCount; ++n) {
    const ImDrawList& list = *draw_data.CmdLists[n];
    const bool touches =
        std::any_of(list.CmdBuffer.begin(), list.CmdBuffer.end(), [&](const ImDrawCmd& command) {
          const PixelBox box = CommandScissor(draw_data, command);
          return std::any_of(regions.begin(), regions.end(), [&](const PixelBox& region) {
            return !Empty(Intersect(box, region));
          });
        });
    if (!touches) continue;
    placed.push_back({&list, static_cast<unsigned>(composed_.VtxBuffer.Size),
                      static_cast<unsigned>(composed_.IdxBuffer.Size)});
    const int vtx = composed_.VtxBuffer.Size, idx = composed_.IdxBuffer.Size;
    composed_.VtxBuffer.resize(vtx + list.VtxBuffer.Size);
    std::memcpy(composed_.VtxBuffer.Data + vtx, list.VtxBuffer.Data,
                static_cast<size_t>(list.VtxBuffer.Size) * sizeof(ImDrawVert));
    composed_.IdxBuffer.resize(idx + list.IdxBuffer.Size);
    std::memcpy(composed_.IdxBuffer.Data + idx, list.IdxBuffer.Data,
                static_cast<size_t>(list.IdxBuffer.Size) * sizeof(ImDrawIdx));
  }
  // Region by region, every command in the original order, its scissor cut to the region.
  for (const PixelBox& region : regions)
    for (const Placed& p : placed)
      for (const ImDrawCmd& command : p.list->CmdBuffer) {
        const PixelBox box = Intersect(CommandScissor(draw_data, command), region);
        if (Empty(box) || command.ElemCount == 0) continue;
        ImDrawCmd clipped = command;
        clipped.ClipRect = ClipRectFor(draw_data, box, fb_height);
        clipped.VtxOffset += p.vtx_base;
        clipped.IdxOffset += p.idx_base;
        composed_.CmdBuffer.push_back(clipped);
      }
  composed_data_ = draw_data;
  composed_data_.CmdLists = &composed_list_;
  composed_data_.CmdListsCount = 1;
  composed_data_.TotalVtxCount = composed_.VtxBuffer.Size;
  composed_data_.TotalIdxCount = composed_.IdxBuffer.Size;
  return &composed_data_;
}

}  // namespace calibench::ui
