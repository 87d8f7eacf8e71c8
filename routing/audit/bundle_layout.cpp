// The pieces of the cables and the cables along each (bundle_layout.hpp).
#include "routing/audit/bundle_layout.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <map>
#include <unordered_map>

namespace loom::audit {

namespace {

/// Relative slack on arc lengths when deciding that a cable's bend pieces follow each other
/// (their lengths are each a Gauss–Legendre sum, to ~10⁻¹² relative).
constexpr double kChainRel = 1e-6;
/// Relative slack on knots (of their range) when deciding that two pieces are one curve.
constexpr double kKnotRel = 1e-9;

/// One piece of one cable before pieces are merged.
struct RawPiece {
  const Centerline* curve = nullptr;
  double s0 = 0.0;
  double length = 0.0;
  bool canon_reversed = false;  ///< its control points run backwards in canonical order
  std::uint64_t key = 0;        ///< hash of degree and control points in canonical order
};

bool lex_less(const Vec3& a, const Vec3& b) {
  return std::lexicographical_compare(a.data(), a.data() + 3, b.data(), b.data() + 3);
}

/// FNV-1a over the degree, the number of control points and the first two and last two
/// in canonical order (first point lexicographically not after the last): equal for a
/// curve and its reverse; candidates with one key are compared in full (same_curve).
RawPiece raw_piece(const Centerline* c, double s0) {
  RawPiece r;
  r.curve = c;
  r.s0 = s0;
  r.length = c->length();
  const auto& cps = c->control_points();
  r.canon_reversed = lex_less(cps.back(), cps.front());
  std::uint64_t h = 1469598103934665603ull;
  auto add = [&h](const void* p, std::size_t n) {
    for (std::size_t i = 0; i < n; ++i) h = (h ^ static_cast<const unsigned char*>(p)[i]) * 1099511628211ull;
  };
  const int deg = c->degree();
  const std::size_t n = cps.size();
  add(&deg, sizeof deg);
  add(&n, sizeof n);
  for (const std::size_t i : {std::size_t{0}, std::size_t{1}, n - 2, n - 1})
    if (i < n) add(cps[r.canon_reversed ? n - 1 - i : i].data(), 3 * sizeof(double));
  r.key = h;
  return r;
}

/// True if b is the curve a, run the same way (reversed false) or backwards (true).
bool same_curve(const Centerline& a, const Centerline& b, bool reversed) {
  const auto& pa = a.control_points();
  const auto& pb = b.control_points();
  const auto& ka = a.knots();
  const auto& kb = b.knots();
  if (a.degree() != b.degree() || pa.size() != pb.size() || ka.size() != kb.size()) return false;
  const std::size_t n = pa.size(), m = ka.size();
  for (std::size_t i = 0; i < n; ++i)
    if (std::memcmp(pa[i].data(), pb[reversed ? n - 1 - i : i].data(), 3 * sizeof(double)) != 0) return false;
  const double ra = ka.back() - ka.front(), rb = kb.back() - kb.front();
  if (!(ra > 0.0) || !(rb > 0.0)) return false;
  for (std::size_t i = 0; i < m; ++i) {
    const double x = (ka[i] - ka.front()) / ra;
    const double y = reversed ? (kb.back() - kb[m - 1 - i]) / rb : (kb[i] - kb.front()) / rb;
    if (std::abs(x - y) > kKnotRel) return false;
  }
  return true;
}

/// The pieces of one cable: its bend pieces where they chain from 0 to its end and its
/// curve starts and ends where they do (within `meet`), else its whole curve.
std::vector<RawPiece> pieces_of(const CableInput& c, double meet) {
  std::vector<RawPiece> out;
  const double L = c.curve.length();
  const double slack = kChainRel * (1.0 + L);
  bool ok = !c.bend_pieces.empty();
  double s = 0.0;
  for (const auto& [s0, piece] : c.bend_pieces) {
    if (piece.empty() || std::abs(s0 - s) > slack) {
      ok = false;
      break;
    }
    out.push_back(raw_piece(&piece, s0));
    s = s0 + out.back().length;
  }
  if (ok) {
    const Centerline& first = c.bend_pieces.front().second;
    const Centerline& last = c.bend_pieces.back().second;
    ok = std::abs(s - L) <= slack &&
         (c.curve.position(c.curve.u_min()) - first.position(first.u_min())).norm() <= meet &&
         (c.curve.position(c.curve.u_max()) - last.position(last.u_max())).norm() <= meet;
  }
  if (!ok) out = {raw_piece(&c.curve, 0.0)};
  return out;
}

/// Junctions of one cable by interned node: (node, position, radius), sorted by node.
using NodeList = std::vector<PieceJunction>;

/// The nodes common to every cable along the piece, each with the smallest radius any of
/// them gives it; a node they place differently is left out.
void common_junctions(Piece& p, const std::vector<NodeList>& nodes_of) {
  p.junctions = nodes_of[static_cast<std::size_t>(p.uses.front().cable)];
  for (std::size_t u = 1; u < p.uses.size() && !p.junctions.empty(); ++u) {
    const NodeList& other = nodes_of[static_cast<std::size_t>(p.uses[u].cable)];
    NodeList kept;
    std::size_t j = 0;
    for (const PieceJunction& x : p.junctions) {
      while (j < other.size() && other[j].node < x.node) ++j;
      if (j < other.size() && other[j].node == x.node && other[j].position == x.position)
        kept.push_back({x.node, x.position, std::min(x.radius, other[j].radius)});
    }
    p.junctions = std::move(kept);
  }
}

/// The harness segment all cables along p list over the whole piece (see Piece), or −1.
int bundle_segment_of(const Piece& p, const std::vector<CableInput>& cables, double meet) {
  if (p.uses.size() < 2) return -1;
  // Both ends must be junctions wide enough that a contact at an end is excused there.
  for (const double u : {p.curve->u_min(), p.curve->u_max()}) {
    const Vec3 end = p.curve->position(u);
    const bool wide = std::any_of(p.junctions.begin(), p.junctions.end(), [&](const PieceJunction& j) {
      return (j.position - end).norm() <= meet && j.radius >= 2.0 * p.r_max * (1.0 + kChainRel) + meet;
    });
    if (!wide) return -1;
  }
  auto covering = [&](const PieceUse& use, int seg) {
    const CableInput& c = cables[static_cast<std::size_t>(use.cable)];
    const double slack = kChainRel * (1.0 + c.curve.length());
    return std::any_of(c.segments.begin(), c.segments.end(), [&](const CableSegmentRange& r) {
      return r.segment == seg && r.s0 <= use.s0 + slack && r.s1 >= use.s0 + use.length - slack;
    });
  };
  const CableInput& first = cables[static_cast<std::size_t>(p.uses.front().cable)];
  for (const CableSegmentRange& r : first.segments) {
    if (r.segment < 0 || !covering(p.uses.front(), r.segment)) continue;
    if (std::all_of(p.uses.begin(), p.uses.end(), [&](const PieceUse& u) { return covering(u, r.segment); }))
      return r.segment;
  }
  return -1;
}

}  // namespace

Layout make_layout(const std::vector<CableInput>& cables, double meet, int threads) {
  Layout lay;
  const std::size_t n = cables.size();
  std::vector<std::vector<RawPiece>> raw(n);
  parallel_indices(n, threads, [&](std::size_t c) { raw[c] = pieces_of(cables[c], meet); });
  // Junction node ids interned, each cable's list sorted by node.
  std::unordered_map<std::string, int> node_id;
  std::vector<NodeList> nodes_of(n);
  for (std::size_t c = 0; c < n; ++c) {
    for (const CableJunction& j : cables[c].junctions) {
      const auto it = node_id.emplace(j.node, static_cast<int>(lay.nodes.size())).first;
      if (it->second == static_cast<int>(lay.nodes.size())) lay.nodes.push_back(j.node);
      nodes_of[c].push_back({it->second, j.position, j.radius});
    }
    std::sort(nodes_of[c].begin(), nodes_of[c].end(),
              [](const PieceJunction& a, const PieceJunction& b) { return a.node < b.node; });
    // A node listed twice by one cable: its smaller radius, its first position.
    NodeList& l = nodes_of[c];
    std::size_t w = 0;
    for (std::size_t k = 0; k < l.size(); ++k) {
      if (w > 0 && l[w - 1].node == l[k].node) {
        l[w - 1].radius = std::min(l[w - 1].radius, l[k].radius);
        continue;
      }
      l[w++] = l[k];
    }
    l.resize(w);
  }
  // Pieces merged by content, in cable order (deterministic).
  std::unordered_multimap<std::uint64_t, int> by_key;
  std::vector<bool> canon_reversed;  // per piece: its first use's RawPiece::canon_reversed
  lay.of_cable.resize(n);
  for (std::size_t c = 0; c < n; ++c)
    for (const RawPiece& rp : raw[c]) {
      int found = -1;
      bool reversed = false;
      const auto range = by_key.equal_range(rp.key);
      for (auto it = range.first; it != range.second && found < 0; ++it) {
        const Piece& p = lay.pieces[static_cast<std::size_t>(it->second)];
        if (p.uses.back().cable == static_cast<int>(c)) continue;  // never with itself
        const bool rev = rp.canon_reversed != canon_reversed[static_cast<std::size_t>(it->second)];
        if (same_curve(*p.curve, *rp.curve, rev)) {
          found = it->second;
          reversed = rev;
        }
      }
      if (found < 0) {
        found = static_cast<int>(lay.pieces.size());
        Piece p;
        p.curve = rp.curve;
        p.length = rp.length;
        lay.pieces.push_back(std::move(p));
        canon_reversed.push_back(rp.canon_reversed);
        by_key.emplace(rp.key, found);
      }
      lay.pieces[static_cast<std::size_t>(found)].uses.push_back(
          {static_cast<int>(c), rp.s0, rp.length, reversed, rp.curve});
    }
  // Each piece on its own (in parallel): its uses by radius, junctions, bundle segment.
  parallel_indices(lay.pieces.size(), threads, [&](std::size_t k) {
    Piece& p = lay.pieces[k];
    std::stable_sort(p.uses.begin(), p.uses.end(), [&](const PieceUse& a, const PieceUse& b) {
      return cables[static_cast<std::size_t>(a.cable)].radius > cables[static_cast<std::size_t>(b.cable)].radius;
    });
    p.r_max = cables[static_cast<std::size_t>(p.uses.front().cable)].radius;
    p.r_min = cables[static_cast<std::size_t>(p.uses.back().cable)].radius;
    common_junctions(p, nodes_of);
    p.bundle_segment = bundle_segment_of(p, cables, meet);
  });
  for (std::size_t k = 0; k < lay.pieces.size(); ++k) {
    const Piece& p = lay.pieces[k];
    if (p.uses.size() > 1) lay.shared = true;
    for (std::size_t u = 0; u < p.uses.size(); ++u)
      lay.of_cable[static_cast<std::size_t>(p.uses[u].cable)].emplace_back(static_cast<int>(k), static_cast<int>(u));
  }
  for (auto& list : lay.of_cable)
    std::sort(list.begin(), list.end(), [&](const std::pair<int, int>& a, const std::pair<int, int>& b) {
      return lay.pieces[static_cast<std::size_t>(a.first)].uses[static_cast<std::size_t>(a.second)].s0 <
             lay.pieces[static_cast<std::size_t>(b.first)].uses[static_cast<std::size_t>(b.second)].s0;
    });
  return lay;
}

}  // namespace loom::audit
