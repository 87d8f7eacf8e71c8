// Bend results of shared curves, once per curve and bend limit (bundle_layout.hpp).
#include "routing/audit/bundle_layout.hpp"

#include <algorithm>
#include <cstring>

namespace loom::audit {

namespace {

/// True if two curves are equal bit for bit (knots and control points): every bend
/// result of one is the other's.
bool identical(const Centerline& a, const Centerline& b) {
  if (&a == &b) return true;
  const auto& ka = a.knots();
  const auto& kb = b.knots();
  const auto& pa = a.control_points();
  const auto& pb = b.control_points();
  return a.degree() == b.degree() && ka.size() == kb.size() && pa.size() == pb.size() &&
         std::memcmp(ka.data(), kb.data(), ka.size() * sizeof(double)) == 0 &&
         std::equal(pa.begin(), pa.end(), pb.begin(), [](const Vec3& x, const Vec3& y) {
           return std::memcmp(x.data(), y.data(), 3 * sizeof(double)) == 0;
         });
}

/// True if the layout's pieces of cable c are its bend pieces in order (or its curve when
/// it has none): the k-th piece is the k-th curve check_bend judges.
bool pieces_are_bend_pieces(const CableInput& in, const Layout& lay, std::size_t c) {
  const auto& list = lay.of_cable[c];
  auto curve_of = [&](std::size_t k) {
    const auto& [piece, use] = list[k];
    return lay.pieces[static_cast<std::size_t>(piece)].uses[static_cast<std::size_t>(use)].curve;
  };
  if (in.bend_pieces.empty()) return list.size() == 1 && curve_of(0) == &in.curve;
  if (list.size() != in.bend_pieces.size()) return false;
  for (std::size_t k = 0; k < list.size(); ++k)
    if (curve_of(k) != &in.bend_pieces[k].second) return false;
  return true;
}

}  // namespace

BendMemo::BendMemo(const Context& ctx, const Layout& lay) : cables_(ctx.cables) {
  const std::size_t n = ctx.cables.size();
  of_cable_.resize(n);
  std::vector<std::vector<double>> limits;  // per group: the bend limits of its cables
  std::vector<std::vector<int>> groups_of_piece(lay.pieces.size());
  for (std::size_t c = 0; c < n; ++c) {
    const CableInput& in = ctx.cables[c];
    if (!pieces_are_bend_pieces(in, lay, c)) continue;
    for (const auto& [piece, use] : lay.of_cable[c]) {
      const Centerline* curve = lay.pieces[static_cast<std::size_t>(piece)].uses[static_cast<std::size_t>(use)].curve;
      auto& gs = groups_of_piece[static_cast<std::size_t>(piece)];
      auto it = std::find_if(gs.begin(), gs.end(), [&](int g) { return identical(*groups_[static_cast<std::size_t>(g)].curve, *curve); });
      int g = it != gs.end() ? *it : -1;
      if (g < 0) {
        g = static_cast<int>(groups_.size());
        groups_.push_back({curve, {}, {}});
        limits.emplace_back();
        gs.push_back(g);
      }
      of_cable_[c].push_back(g);
      if (ctx.req.check_bend && in.min_bend_radius > 0.0) limits[static_cast<std::size_t>(g)].push_back(in.min_bend_radius);
    }
  }
  parallel_indices(groups_.size(), ctx.req.threads, [&](std::size_t g) {
    Group& gr = groups_[g];
    gr.min = gr.curve->min_bend_radius();
    std::vector<double>& l = limits[g];
    std::sort(l.begin(), l.end());
    l.erase(std::unique(l.begin(), l.end()), l.end());
    for (const double limit : l)
      if (gr.min.radius < limit) gr.below.emplace_back(limit, gr.curve->bend_stretches_below(limit));
  });
}

const BendExtremum* BendMemo::min_radius(std::size_t c, std::size_t k) const {
  if (k >= of_cable_[c].size()) return nullptr;
  return &groups_[static_cast<std::size_t>(of_cable_[c][k])].min;
}

const std::vector<BendExtremum>* BendMemo::below(std::size_t c, std::size_t k) const {
  if (k >= of_cable_[c].size()) return nullptr;
  const Group& g = groups_[static_cast<std::size_t>(of_cable_[c][k])];
  const double limit = cables_[c].min_bend_radius;
  for (const auto& [l, stretches] : g.below)
    if (l == limit) return &stretches;
  static const std::vector<BendExtremum> none;
  return g.min.radius >= limit ? &none : nullptr;  // nothing bends tighter than it
}

}  // namespace loom::audit
