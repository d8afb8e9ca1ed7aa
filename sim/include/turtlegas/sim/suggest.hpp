// SPDX-License-Identifier: MIT
// Lists of names in messages: "known: a, b, c", and "did you mean" for a close misspelling. Shared
// by every reader of names (the world-file loader, `expect`, games, the controller registry), as
// format.hpp's numbers are.
#pragma once

#include <algorithm>
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace turtlegas::sim {

/// Levenshtein distance.
inline std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diag = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diag = up;
    }
  }
  return row[b.size()];
}

/// `; did you mean "count"?` for a close misspelling (fewer than 3 edits) of one of `known`,
/// else empty. `quote` goes around the suggestion.
inline std::string suggestion(std::string_view key, const auto& known, std::string_view quote = "\"") {
  std::string best;
  std::size_t best_distance = 3;
  for (std::string_view k : known) {
    const std::size_t d = edit_distance(key, k);
    if (d < best_distance) best_distance = d, best = k;
  }
  if (best.empty()) return {};
  std::string s = "; did you mean ";
  s += quote;
  s += best;
  s += quote;
  s += '?';
  return s;
}

/// "a, b, c": the names in `known`, in their order, each between two `quote`s when one is given.
inline std::string join_names(const auto& known, std::string_view quote = {}) {
  std::string s;
  for (std::string_view k : known) {
    if (!s.empty()) s += ", ";
    s += quote;
    s += k;
    s += quote;
  }
  return s;
}

}  // namespace turtlegas::sim
