// SPDX-License-Identifier: MIT
// Discs in hashed cells sized by their radii, for the scene checks (validate()'s overlaps): a
// grid laid over the arena made 1e5 discs clustered in a 1e9 arena share one cell and their check
// O(N^2) (issue 29); these cells exist only where there are discs, so the check is ~O(N log N)
// wherever they are.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "turtlegas/sim/vec2.hpp"

namespace turtlegas::sim {

/// Items (32-bit numbers whose meaning the caller keeps) entered for discs in square cells of
/// levels: level l has cells of side side0 * 2^l, and a disc is entered at the lowest level whose
/// cells are at least its diameter, in the cells its bounding box covers there (at most 2 x 2).
/// Two discs that overlap have overlapping boxes, so they share a cell at the higher of their two
/// levels; near() looks at a disc's own level and every higher one in use, where its box covers
/// at most 2 x 2 cells, so it sees every disc it overlaps that sits at a level no lower than its
/// own (a pair is seen from the disc at the lower level, or from both). Cells are keyed by a
/// 64-bit hash of (level, column, row); two cells whose keys collide merely share their lists.
/// Fill with add(), then build(), then ask near().
class DiscGrid {
 public:
  /// Level 0's cell side: about the discs' typical diameter (1 if it is not > 0).
  explicit DiscGrid(double side0) : side0_(side0 > 0.0 ? side0 : 1.0) {}

  void reserve(std::size_t entries) { entries_.reserve(entries); }

  /// Enters item for the disc at c of radius r.
  void add(Vec2 c, double r, std::uint32_t item) {
    const int l = level(r);
    const double side = std::ldexp(side0_, l);
    for_cells(c, r, side, [&](std::int64_t ix, std::int64_t iy) {
      entries_.push_back({key(l, ix, iy), item});
      return false;
    });
    if (std::find(levels_.begin(), levels_.end(), l) == levels_.end()) levels_.push_back(l);
  }

  /// Sorts the entries by cell and indexes the cells; add() no more after it.
  void build() {
    std::sort(entries_.begin(), entries_.end(),
              [](const Entry& a, const Entry& b) { return a.key < b.key || (a.key == b.key && a.item < b.item); });
    std::sort(levels_.begin(), levels_.end());
    std::size_t cells = 0;
    for (std::size_t e = 0; e < entries_.size(); ++e) cells += e == 0 || entries_[e].key != entries_[e - 1].key;
    std::size_t capacity = 16;
    while (capacity < 2 * cells) capacity *= 2;
    table_.assign(capacity, npos);
    for (std::size_t e = 0; e < entries_.size(); ++e) {
      if (e > 0 && entries_[e].key == entries_[e - 1].key) continue;
      std::size_t slot = entries_[e].key & (capacity - 1);
      while (table_[slot] != npos) slot = (slot + 1) & (capacity - 1);
      table_[slot] = static_cast<std::uint32_t>(e);
    }
  }

  /// Calls f(item) for every item entered at the level of a disc of radius r, or a higher one, in
  /// a cell that the box of the disc at c covers (an item may be seen more than once); stops and
  /// returns true as soon as f returns true.
  template <class F>
  bool near(Vec2 c, double r, F&& f) const {
    const int own = level(r);
    for (const int l : levels_) {
      if (l < own) continue;
      const bool stop = for_cells(c, r, std::ldexp(side0_, l), [&](std::int64_t ix, std::int64_t iy) {
        const std::uint64_t k = key(l, ix, iy);
        const std::size_t mask = table_.size() - 1;
        for (std::size_t slot = k & mask; table_[slot] != npos; slot = (slot + 1) & mask) {
          if (entries_[table_[slot]].key != k) continue;
          for (std::size_t e = table_[slot]; e < entries_.size() && entries_[e].key == k; ++e)
            if (f(entries_[e].item)) return true;
          return false;
        }
        return false;
      });
      if (stop) return true;
    }
    return false;
  }

  /// CoverGrid's interface, for code that searches either: near(c, r, f) as any(cover_disc(c, r), f).
  struct Query {
    Vec2 c;
    double r;
  };
  Query cover_disc(Vec2 c, double r) const { return {c, r}; }
  template <class F>
  bool any(Query q, F&& f) const {
    return near(q.c, q.r, f);
  }

  /// The level of a disc of radius r: the lowest l with side0 2^l >= 2 r.
  int level(double r) const {
    if (!(2.0 * r > side0_)) return 0;
    int l = std::max(0, static_cast<int>(std::ceil(std::log2(2.0 * r / side0_))));
    while (l > 0 && std::ldexp(side0_, l - 1) >= 2.0 * r) --l;
    while (std::ldexp(side0_, l) < 2.0 * r && l < kMaxLevel) ++l;
    return l;
  }

 private:
  static constexpr std::uint32_t npos = std::numeric_limits<std::uint32_t>::max();
  static constexpr int kMaxLevel = 4096;  // beyond double's range: side0 2^l is infinite there
  struct Entry {
    std::uint64_t key;
    std::uint32_t item;
  };

  // The column (or row) of coordinate u in cells of side s, clamped to +-2^62 (a clamp is
  // monotone, so overlapping boxes still share a cell).
  static std::int64_t index(double u, double s) {
    const double q = std::floor(u / s);
    constexpr double lim = 0x1p62;
    if (!(q > -lim)) return -static_cast<std::int64_t>(lim);
    if (q >= lim) return static_cast<std::int64_t>(lim);
    return static_cast<std::int64_t>(q);
  }

  // Calls g(ix, iy) for the cells of side s that the box of the disc (c, r) covers; stops when g
  // returns true, and says so.
  template <class G>
  static bool for_cells(Vec2 c, double r, double s, G&& g) {
    const std::int64_t x0 = index(c.x - r, s), x1 = index(c.x + r, s);
    const std::int64_t y0 = index(c.y - r, s), y1 = index(c.y + r, s);
    for (std::int64_t iy = y0; iy <= y1; ++iy)
      for (std::int64_t ix = x0; ix <= x1; ++ix)
        if (g(ix, iy)) return true;
    return false;
  }

  // splitmix64's finaliser over the three numbers: the low bits index the table.
  static std::uint64_t key(int level, std::int64_t ix, std::int64_t iy) {
    auto mix = [](std::uint64_t z) {
      z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
      z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
      return z ^ (z >> 31);
    };
    std::uint64_t h = mix(static_cast<std::uint64_t>(level) + 0x9e3779b97f4a7c15ULL);
    h = mix(h ^ static_cast<std::uint64_t>(ix));
    return mix(h ^ (static_cast<std::uint64_t>(iy) + 0x9e3779b97f4a7c15ULL));
  }

  double side0_;
  std::vector<Entry> entries_;
  std::vector<std::uint32_t> table_;
  std::vector<int> levels_;  ///< the levels in use, ascending after build()
};

}  // namespace turtlegas::sim
