#include "grid/label_table.h"

namespace puzzlecal {
namespace {
constexpr uint64_t kEmpty = ~uint64_t{0};
}  // namespace

LabelTable::LabelTable(int max_entries) {
  size_t capacity = 16;
  while (capacity < 2 * static_cast<size_t>(max_entries)) capacity *= 2;
  keys_.assign(capacity, kEmpty);
  values_.assign(capacity, -1);
  mask_ = capacity - 1;
}

uint64_t LabelTable::Key(int tree, const Eigen::Vector2i& label) {
  // 22 bits per label coordinate (offset to be non-negative), tree above.
  const uint64_t i = static_cast<uint64_t>(label.x() + kMaxLabel + 1);
  const uint64_t j = static_cast<uint64_t>(label.y() + kMaxLabel + 1);
  return (static_cast<uint64_t>(tree) << 44) | (i << 22) | j;
}

size_t LabelTable::Slot(uint64_t key) const {
  // splitmix64 finaliser.
  key ^= key >> 30;
  key *= 0xbf58476d1ce4e5b9ULL;
  key ^= key >> 27;
  key *= 0x94d049bb133111ebULL;
  key ^= key >> 31;
  return static_cast<size_t>(key) & mask_;
}

int LabelTable::Find(int tree, const Eigen::Vector2i& label) const {
  const uint64_t key = Key(tree, label);
  for (size_t s = Slot(key);; s = (s + 1) & mask_) {
    if (keys_[s] == key) return values_[s];
    if (keys_[s] == kEmpty) return -1;
  }
}

void LabelTable::Insert(int tree, const Eigen::Vector2i& label, int corner) {
  const uint64_t key = Key(tree, label);
  size_t s = Slot(key);
  while (keys_[s] != kEmpty && keys_[s] != key) s = (s + 1) & mask_;
  keys_[s] = key;
  values_[s] = corner;
}

void LabelTable::Erase(int tree, const Eigen::Vector2i& label) {
  const uint64_t key = Key(tree, label);
  size_t s = Slot(key);
  while (keys_[s] != key) {
    if (keys_[s] == kEmpty) return;
    s = (s + 1) & mask_;
  }
  // Backward-shift: move later entries of the probe run into the hole.
  size_t hole = s;
  for (size_t next = (hole + 1) & mask_; keys_[next] != kEmpty;
       next = (next + 1) & mask_) {
    const size_t home = Slot(keys_[next]);
    // The entry may move to the hole when its home is not in (hole, next].
    const bool home_in_between = (hole < next) ? (home > hole && home <= next)
                                               : (home > hole || home <= next);
    if (!home_in_between) {
      keys_[hole] = keys_[next];
      values_[hole] = values_[next];
      hole = next;
    }
  }
  keys_[hole] = kEmpty;
  values_[hole] = -1;
}

}  // namespace puzzlecal
