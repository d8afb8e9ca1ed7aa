// SPDX-License-Identifier: MIT
// The bracketed search of the general pair's gap (pair_gap.hpp).
#include "pair_gap.hpp"

#include <algorithm>
#include <cmath>

namespace turtlegas::sim::field_toi_detail {
namespace {

// The largest s such that lo + G s' - M s'^2 / 2 > 0 for all s' in [0, s), lo > 0: the positive
// root, in the form that adds quantities of the same sign.
double safe_step(double lo, double G, double M) {
  if (!(lo > 0.0)) return 0.0;
  const double sq = std::sqrt(G * G + 2.0 * M * lo);
  if (G < 0.0) return 2.0 * lo / (sq - G);
  return M > 0.0 ? (G + sq) / M : kNever;
}

struct Node {
  double a, b;
  PairSample sa, sb;
};

// The search of toi_field_disc_disc_bracketed on [t_begin, t_end], s_begin the sample at t_begin.
//
// On a node [a, b] (h = b - a) the bounds A >= |r''|, |r'| <= V = |r'(a)| + A h and |r| <= R =
// |r(a)| + |r'(a)| h + A h^2/2 (or the same from b, whichever is smaller) give
//   -M_lo <= g'' <= M_hi,  M_lo = 2 R A,  M_hi = 2 V^2 + 2 R A,
// so from either end g lies between two parabolas. With the evaluation errors subtracted:
//   * g > 0 on the node if the lower parabolas from a and from b, positive at their ends, stay
//     positive over lengths that together cover h (safe_step; the envelopes' bound, when both
//     bodies have one, may lengthen them: PairGap::envelope_step); g < 0 likewise with the upper
//     parabolas;
//   * g is monotone if g'(a) + M_hi h < 0 or g'(b) + M_lo h < 0 (falling), or the mirror (rising).
// A node whose computed ends fall (g(a) >= 0 > g(b)) and is monotone is refined; a node proven
// positive, negative or monotone without such a fall holds no fall (of the exact g, deeper than the
// evaluation error) and is dropped; every other node is split, leftmost first, so the first fall is
// found first. Nodes narrower than 4 eps t_end are decided by their end points' signs alone: a dip
// missed there is shallower than M_hi (4 eps t_end)^2 / 2.
//
// A call stops after kMaxSplits splits, but never by deciding a node on its ends: the nodes are
// taken leftmost first, so when it stops at node [a, b] every node left of a has been dropped (proven
// free of a fall) and [t_begin, a] holds none. It returns {kNever, a}: "nothing up to a", and the
// caller continues from there (toi_field_disc_disc_bracketed re-centres the flights at a; the engine
// could re-predict there instead). It stops only when a > t_begin, so each call makes progress
// (a node whose left end is still t_begin can be split only by halving, at most ~50 times down to
// 4 eps t_end, or trimmed from the right, by a quarter each time: a bounded number of splits).
// The stack cannot overflow: it holds one right sibling per halving on the path to the current
// node (a trim replaces a node by one), and a path has at most log2(1 / (4 eps)) = 50 halvings
// before its nodes are below 4 eps t_end; 160 entries leave room to spare (if it ever were full the
// call would stop at the node, as above, rather than decide it on its ends).
constexpr int kMaxSplits = 4000;

}  // namespace

PartialToi bracketed_search(const PairGap& pg, double t_begin, const PairSample& s_begin, double t_end) {
  const double A = pg.acc_bound();
  const double h_min = 4.0 * kEps * t_end;
  Node stack[160];
  int top = 0;
  stack[top++] = {t_begin, t_end, s_begin, pg.sample(t_end)};
  int splits = 0;
  constexpr double kInflate = 1.0 + 1e-12;  // the bounds' own rounding
  while (top > 0) {
    const Node nd = stack[--top];
    if ((splits >= kMaxSplits || top + 2 > 160) && nd.a > t_begin) return {kNever, nd.a};
    const double h = nd.b - nd.a;
    const PairSample& sa = nd.sa;
    const PairSample& sb = nd.sb;
    const double V = std::min(sa.v, sb.v) + A * h;
    const double R = std::min(sa.r + sa.v * h, sb.r + sb.v * h) + 0.5 * A * h * h;
    const double m_lo = kInflate * 2.0 * R * A;
    const double m_hi = kInflate * (2.0 * V * V + 2.0 * R * A);
    const bool falling = sa.dg + sa.edg + m_hi * h < 0.0 || sb.dg + sb.edg + m_lo * h < 0.0;
    const bool rising = sa.dg - sa.edg - m_lo * h > 0.0 || sb.dg - sb.edg - m_hi * h > 0.0;
    const bool can_split = h > h_min && top + 2 <= 160;
    const bool fall_between = sa.g >= 0.0 && sb.g < 0.0;
    auto refine = [&] {
      return PartialToi{
          refine_fall_newton([&](double t) { return pg.gap_d(t); }, nd.a, GapD{sa.g, sa.dg}, nd.b, GapD{sb.g, sb.dg}),
          t_end};
    };
    if (fall_between && (falling || !can_split)) return refine();
    if (!fall_between && (falling || rising || !can_split)) continue;
    // The parts next to each end on which g keeps that end's sign, proven by the parabolas.
    // A positive end also gets the envelopes' step.
    const double step_a = sa.g >= 0.0 ? std::max(safe_step(sa.g - sa.eg, sa.dg - sa.edg, m_lo), pg.envelope_step(nd.a))
                                       : safe_step(-(sa.g + sa.eg), -(sa.dg + sa.edg), m_hi);
    const double step_b = sb.g >= 0.0
                              ? std::max(safe_step(sb.g - sb.eg, -(sb.dg + sb.edg), m_lo), pg.envelope_step(nd.b))
                              : safe_step(-(sb.g + sb.eg), sb.dg - sb.edg, m_hi);
    if (step_a + step_b >= h) {
      if (fall_between) return refine();  // only by rounding: the fall is at the seam
      continue;
    }
    ++splits;
    // Drop the proven parts when they are a good share of the node (near a root this steps
    // towards it like conservative advancement); otherwise halve.
    if (step_a >= 0.25 * h || step_b >= 0.25 * h) {
      const double a = step_a >= 0.25 * h ? nd.a + step_a : nd.a;
      const double b = step_b >= 0.25 * h ? nd.b - step_b : nd.b;
      stack[top++] = {a, b, a == nd.a ? sa : pg.sample(a), b == nd.b ? sb : pg.sample(b)};
      continue;
    }
    const double m = nd.a + 0.5 * h;
    const PairSample sm = pg.sample(m);
    stack[top++] = {m, nd.b, sm, sb};
    stack[top++] = {nd.a, m, sa, sm};
  }
  return {kNever, t_end};
}

}  // namespace turtlegas::sim::field_toi_detail
