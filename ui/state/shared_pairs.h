// The pairs a workbench's snapshot shows, as one immutable list that the controller's state and
// every snapshot taken of it share: a snapshot (one per frame) copies a pointer, never the pairs
// (docs/architecture.md, "One state"). Only the controller changes it, under its mutex; a change
// while a snapshot still holds the list makes a new one (copy on write), so a panel reading its
// snapshot on the window thread never sees a pair change under it. No GL, no ImGui.
#pragma once

#include <cstddef>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace calibench::ui {

template <typename Pair>
class SharedPairs {
 public:
  SharedPairs() = default;
  explicit SharedPairs(std::vector<Pair> pairs)
      : pairs_(std::make_shared<std::vector<Pair>>(std::move(pairs))) {}

  // Reading: what a std::vector offers a reader.
  size_t size() const { return pairs_ ? pairs_->size() : 0; }
  bool empty() const { return size() == 0; }
  const Pair& operator[](size_t index) const { return (*pairs_)[index]; }
  const Pair& at(size_t index) const {
    if (index >= size())
      throw std::out_of_range("pair " + std::to_string(index) + " of " + std::to_string(size()));
    return (*pairs_)[index];
  }
  typename std::vector<Pair>::const_iterator begin() const { return All().begin(); }
  typename std::vector<Pair>::const_iterator end() const { return All().end(); }

  // Changing (the controller, with its mutex held; every snapshot is copied under that mutex, so
  // no copy is being made while the count is read): the list this state alone holds, copied
  // first when a snapshot holds it too. A reference stays valid until the next snapshot.
  std::vector<Pair>& Edit() {
    if (!pairs_)
      pairs_ = std::make_shared<std::vector<Pair>>();
    else if (pairs_.use_count() > 1)
      pairs_ = std::make_shared<std::vector<Pair>>(*pairs_);
    return *pairs_;
  }
  Pair& Edit(size_t index) { return Edit().at(index); }

  // True when both hold the same list (a snapshot of an unchanged state; tests).
  bool SharesWith(const SharedPairs& other) const { return pairs_ == other.pairs_; }

 private:
  const std::vector<Pair>& All() const {
    static const std::vector<Pair> kNone;
    return pairs_ ? *pairs_ : kNone;
  }

  std::shared_ptr<std::vector<Pair>> pairs_;
};

}  // namespace calibench::ui
