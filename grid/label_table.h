#ifndef PUZZLECAL_GRID_LABEL_TABLE_H_
#define PUZZLECAL_GRID_LABEL_TABLE_H_

#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace puzzlecal {

// (tree, lattice label) -> corner, an open-addressing hash table with linear
// probing and backward-shift deletion: fixed capacity, no allocation after
// construction. Labels must lie within +-kMaxLabel.
class LabelTable {
 public:
  static constexpr int kMaxLabel = (1 << 20) - 1;

  // Room for `max_entries` entries at a load factor of at most 1/2.
  explicit LabelTable(int max_entries);

  // The corner at `label` in tree `tree`, or -1.
  int Find(int tree, const Eigen::Vector2i& label) const;
  // Adds or replaces.
  void Insert(int tree, const Eigen::Vector2i& label, int corner);
  // Removes the entry if present.
  void Erase(int tree, const Eigen::Vector2i& label);

 private:
  static uint64_t Key(int tree, const Eigen::Vector2i& label);
  size_t Slot(uint64_t key) const;

  std::vector<uint64_t> keys_;  // kEmpty for free slots
  std::vector<int> values_;
  size_t mask_ = 0;
};

}  // namespace puzzlecal

#endif  // PUZZLECAL_GRID_LABEL_TABLE_H_
