// SPDX-License-Identifier: MIT
// The overlap measure: World::measure_overlap, and through it the CLI's max_overlap and expect's.
#include "overlap.hpp"

namespace turtlegas::sim::detail {

Overlap deepest_overlap(const DiscView& discs, const std::vector<Segment>& walls, double periodic_width, double periodic_height,
                        bool ball_pairs, const std::vector<Layers>* body_layers, const std::vector<Layers>* wall_layers) {
  OverlapScratch scratch;
  return deepest_overlap(scratch, discs.n, discs.pos, discs.radius, discs.alive, walls, periodic_width, periodic_height,
                         ball_pairs, body_layers, wall_layers);
}

}  // namespace turtlegas::sim::detail
