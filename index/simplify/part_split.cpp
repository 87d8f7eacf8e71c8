// Splitting a blocked part (AlphaSimOptions::split_blocked): a part whose three projections
// hide a feature — a cavity, a channel turning a corner, a housing's interior — fills space
// a cable could use, so α-SIM keeps its original. Cut into slabs around the hidden space,
// the pieces show it in their own projections: a slab across a cavity sees its walls as a
// frame. Each piece is simplified on its own, and the union of the pieces is the part.
#include "index/simplify/alpha_sim.hpp"

#include "core/stopwatch.hpp"
#include "index/embree_index.hpp"
#include "index/simplify/lost_space.hpp"
#include "index/simplify/mesh_cut.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace loom {

namespace {

/// The slab around a lost ball of radius ρ reaches at least ρ·√½ on either side of its centre: the
/// cylinder of that radius through the slab lies inside the ball, so the slab's projection
/// along the cut axis shows a hole of radius ρ·√½ ≥ 1.4·dim_pre (the ball is ≥ 2·dim_pre),
/// wider than α, which the α-shape keeps open.
constexpr double kSlabHalfWidth = 0.70710678118654752;
/// A cut is made this share of dim_pre short of the material that ends a free run: a face
/// in the cut plane would go to the slab and cover the hole in its projection.
constexpr double kCutBackoff = 0.25;
/// Sphere-tracing steps when measuring the free run from a lost ball's centre.
constexpr int kFreeRunSteps = 256;

const char* axis_name(int a) { return a == 0 ? "x" : a == 1 ? "y" : "z"; }

/// Cuts `mesh` along axis a at the increasing coordinates `at`: the slabs in order, and in
/// `cuts` each one's bounds as text ("lo <= x <= hi", the outer ends from `box`).
std::vector<Mesh> cut_into_slabs(const Mesh& mesh, int a, const std::vector<double>& at, const AABB& box,
                                 std::vector<std::string>& cuts) {
  auto bounds = [&](double s0, double s1) {
    return full_precision(s0) + " <= " + axis_name(a) + " <= " + full_precision(s1);
  };
  std::vector<Mesh> out;
  cuts.clear();
  Mesh rest = mesh;
  double from = box.min[a];
  for (const double x : at) {
    MeshHalves h = cut_mesh(rest, a, x);
    out.push_back(std::move(h.below));
    cuts.push_back(bounds(from, x));
    rest = std::move(h.above);
    from = x;
  }
  out.push_back(std::move(rest));
  cuts.push_back(bounds(from, box.max[a]));
  return out;
}

/// The split of one blocked part: the tree of pieces, their meshes and solids.
class PartSplitter {
 public:
  PartSplitter(const Part& part, const AlphaSimOptions& opt, AlphaSimPart whole)
      : part_(part), opt_(opt), whole_(std::move(whole)), original_(whole_index(part)) {
    piece_opt_ = opt;
    // Pieces are open: their lost space is probed here against the whole part.
    piece_opt_.detect_lost_space = false;
    piece_opt_.step_dir.clear();
    piece_opt_.progress = nullptr;
    // Every piece keeps the part's tolerance.
    if (!(piece_opt_.scene_size > 0.0)) piece_opt_.scene_size = part.mesh.bounds().diagonal();
    r_lost_ = opt.lost_space_factor * opt.dim_pre;
  }

  AlphaSimPart run();

 private:
  static EmbreeIndex whole_index(const Part& part) {
    std::vector<Part> one(1);
    one[0].name = part.name;
    one[0].mesh = part.mesh;
    one[0].closed = true;
    return EmbreeIndex(one);
  }
  /// Simplifies the piece `mesh` and, while it is blocked and may be cut, its children.
  void process(Mesh mesh, const std::string& id, const std::string& cut, int depth);
  /// process() on each non-empty slab k, as piece prefix + k.
  void process_all(std::vector<Mesh> slabs, const std::vector<std::string>& cuts, const std::string& prefix,
                   int depth) {
    for (std::size_t k = 0; k < slabs.size(); ++k)
      if (!slabs[k].empty()) process(std::move(slabs[k]), prefix + std::to_string(k), cuts[k], depth);
  }
  /// Cuts `mesh` into up to three slabs across the hidden space around the lost ball;
  /// empty when no axis allows a cut that leaves every piece at least dim_pre thick.
  /// `cuts` gets each slab's bounds.
  std::vector<Mesh> cut_around(const Mesh& mesh, const AABB& box, const LostSpace& ball,
                               std::vector<std::string>& cuts) const;
  /// Length of free space from c along ±axis within box (sphere tracing on the original).
  double free_run(const Vec3& c, int axis, double sign, const AABB& box) const;
  /// The result: the union of the leaves, or the original with the tree and the reason.
  AlphaSimPart assemble(const std::string& failure);

  const Part& part_;
  const AlphaSimOptions& opt_;
  AlphaSimOptions piece_opt_;
  AlphaSimPart whole_;
  EmbreeIndex original_;
  double r_lost_ = 0.0;
  std::vector<AlphaSimPiece> tree_;
  std::vector<AlphaSimPart> leaves_;  ///< simplified leaves, in tree order
  std::size_t pieces_ = 0;            ///< pieces made so far (inner nodes and leaves)
  std::string failure_;               ///< why the first leaf could not be simplified
  LostSpace whole_lost_;              ///< the ball the whole part hid
};

double PartSplitter::free_run(const Vec3& c, int axis, double sign, const AABB& box) const {
  Vec3 dir = Vec3::Zero();
  dir[axis] = sign;
  const double eps = 1e-3 * opt_.dim_pre;
  double t = 0.0;
  for (int i = 0; i < kFreeRunSteps; ++i) {
    const Vec3 p = c + t * dir;
    if (!box.contains(p)) break;
    const double d = original_.closest(p).distance;
    if (d < eps) break;
    t += d;
  }
  return t;
}

std::vector<Mesh> PartSplitter::cut_around(const Mesh& mesh, const AABB& box, const LostSpace& ball,
                                           std::vector<std::string>& cuts) const {
  // The slab along axis a runs as far as the hidden space is free: the shortest free run
  // from the ball's centre and from four points half its radius off it (a line through a
  // window in a wall would run on through the window). Cut a little short of the material
  // that ends the run, so that its face stays outside the slab, and never narrower than
  // the slab the ball itself guarantees.
  const double half = 0.5 * ball.radius, back = kCutBackoff * opt_.dim_pre;
  std::array<std::array<double, 2>, 3> run;  // [axis][below, above]
  for (int a = 0; a < 3; ++a) {
    const int b = (a + 1) % 3, c = (a + 2) % 3;
    std::array<Vec3, 5> starts;
    starts.fill(ball.center);
    starts[1][b] += half;
    starts[2][b] -= half;
    starts[3][c] += half;
    starts[4][c] -= half;
    for (int side = 0; side < 2; ++side) {
      double shortest = std::numeric_limits<double>::infinity();
      for (const Vec3& s : starts) shortest = std::min(shortest, free_run(s, a, side == 0 ? -1.0 : 1.0, box));
      run[a][side] = std::max(shortest - back, kSlabHalfWidth * ball.radius);
    }
  }
  // The axis along which the hidden space runs farthest first: a slab across it sees the
  // space's cross-section (a trough seen end-on, a cavity seen through its side walls).
  std::array<int, 3> order{0, 1, 2};
  std::stable_sort(order.begin(), order.end(),
                   [&](int l, int r) { return run[l][0] + run[l][1] > run[r][0] + run[r][1]; });
  for (const int a : order) {
    const double lo = ball.center[a] - run[a][0], hi = ball.center[a] + run[a][1];
    // A cut that would leave a piece thinner than dim_pre is not made; the slab runs on
    // to the piece's end instead.
    const bool cut_lo = lo - box.min[a] >= opt_.dim_pre, cut_hi = box.max[a] - hi >= opt_.dim_pre;
    if (!cut_lo && !cut_hi) continue;
    std::vector<double> at;
    if (cut_lo) at.push_back(lo);
    if (cut_hi) at.push_back(hi);
    return cut_into_slabs(mesh, a, at, box, cuts);
  }
  return {};
}

void PartSplitter::process(Mesh mesh, const std::string& id, const std::string& cut, int depth) {
  ++pieces_;
  AlphaSimPiece node;
  node.id = id;
  node.cut = cut;
  node.box = mesh.bounds();
  node.triangles_before = mesh.triangle_count();
  Part piece;
  piece.name = part_.name + "#" + id;
  piece.mesh = std::move(mesh);
  AlphaSimPart sp = simplify_part(piece, piece_opt_);
  node.status = sp.result.status;
  node.reason = sp.result.reason;
  node.triangles_after = sp.result.triangles_after;
  node.containment = sp.result.containment;
  const std::size_t at = tree_.size();
  tree_.push_back(node);
  if (sp.result.fallback == AlphaSimFallback::Original) {
    // A piece whose mesh could not be built (a Boolean that lost part of the prisms'
    // intersection) is halved across its longest side and tried again, as smaller pieces.
    const Vec3 ext = node.box.size();
    int a = 0;
    for (int k = 1; k < 3; ++k)
      if (ext[k] > ext[a]) a = k;
    if (sp.result.status == AlphaSimStatus::Failed && ext[a] >= 2.0 * opt_.dim_pre && depth < opt_.split_max_depth &&
        pieces_ + 2 <= opt_.split_max_pieces) {
      std::vector<std::string> halves;
      std::vector<Mesh> children = cut_into_slabs(piece.mesh, a, {node.box.center()[a]}, node.box, halves);
      tree_[at].leaf = false;
      tree_[at].reason += "; halved";
      process_all(std::move(children), halves, id + ".", depth + 1);
      return;
    }
    if (failure_.empty()) failure_ = "piece " + id + ": " + sp.result.reason;
    return;
  }
  const LostSpace lost =
      probe_lost_space({sp.solid.get()}, original_, node.box, r_lost_ / 2.0, opt_.lost_space_max_samples);
  tree_[at].lost_space_radius = lost.radius;
  if (lost.radius < r_lost_) {
    leaves_.push_back(std::move(sp));
    return;
  }
  // Blocked: cut again where that is allowed.
  std::vector<std::string> cuts;
  std::vector<Mesh> children;
  if (depth < opt_.split_max_depth && pieces_ + 3 <= opt_.split_max_pieces)
    children = cut_around(piece.mesh, node.box, lost, cuts);
  tree_[at].status = AlphaSimStatus::Blocked;
  if (children.empty()) {
    tree_[at].reason = "a ball of radius " + full_precision(lost.radius) + " at " + full_precision(lost.center) +
                       " is still hidden, and " +
                       (depth >= opt_.split_max_depth ? "the split is " + std::to_string(depth) + " levels deep"
                        : pieces_ + 3 > opt_.split_max_pieces
                            ? "the part has " + std::to_string(pieces_) + " pieces"
                            : std::string("no cut leaves every piece dim_pre thick"));
    tree_[at].triangles_after = tree_[at].triangles_before;
    if (failure_.empty()) failure_ = "piece " + id + ": " + tree_[at].reason;
    return;
  }
  tree_[at].leaf = false;
  tree_[at].reason = "a ball of radius " + full_precision(lost.radius) + " at " + full_precision(lost.center) +
                     " is hidden: cut again";
  tree_[at].triangles_after = 0;
  process_all(std::move(children), cuts, id + ".", depth + 1);
}

AlphaSimPart PartSplitter::assemble(const std::string& failure) {
  AlphaSimPart out = std::move(whole_);
  AlphaSimResult& r = out.result;
  r.pieces = std::move(tree_);
  if (!failure.empty()) {
    r.reason += "; split into " + std::to_string(r.pieces.size()) + " pieces, but " + failure;
    return out;
  }
  Mesh mesh;
  std::vector<std::shared_ptr<const AlphaSimSolid>> solids;
  bool hull = false, occt = false, cgal = false;
  r.faces_after = 0;
  r.volume_after = 0.0;
  r.containment = r.containment_implicit = 1.0;
  r.containment_samples = 0;
  r.hausdorff = r.float_rounding = 0.0;
  r.prisms_absorbed = r.booleans = 0;
  for (AlphaSimPart& leaf : leaves_) {
    const AlphaSimResult& l = leaf.result;
    mesh.append(leaf.mesh);
    solids.push_back(leaf.solid);
    hull |= l.status == AlphaSimStatus::HullFallback;
    occt |= l.booleans_by == "opencascade";
    cgal |= l.booleans_by == "cgal";
    r.faces_after += l.faces_after;
    r.volume_after += l.volume_after;  // pieces overlap only within the prisms' margin
    r.containment = std::min(r.containment, l.containment);
    r.containment_implicit = std::min(r.containment_implicit, l.containment_implicit);
    r.containment_samples += l.containment_samples;
    r.hausdorff = std::max(r.hausdorff, l.hausdorff);
    r.float_rounding = std::max(r.float_rounding, l.float_rounding);
    r.prisms_absorbed += l.prisms_absorbed;
    r.booleans += l.booleans;
    r.shapes_ms += l.shapes_ms;
    r.mesh_ms += l.mesh_ms;
    r.measure_ms += l.measure_ms;
  }
  r.triangles_after = mesh.triangle_count();
  r.status = hull ? AlphaSimStatus::HullFallback : AlphaSimStatus::Ok;
  r.fallback = hull ? AlphaSimFallback::ConvexHull : AlphaSimFallback::None;
  r.booleans_by = occt ? "opencascade" : cgal ? "cgal" : "none";
  r.closed_after = true;  // each piece is closed
  r.reason = "split into " + std::to_string(leaves_.size()) + " pieces: the whole part hid a ball of radius " +
             full_precision(whole_lost_.radius) + " at " + full_precision(whole_lost_.center) + " in every projection";
  out.mesh = std::move(mesh);
  out.solid.reset();
  out.piece_solids = std::move(solids);
  return out;
}

AlphaSimPart PartSplitter::run() {
  const Stopwatch t0;
  const double whole_ms = whole_.result.time_ms;
  // The first cut is around the ball the whole part's probe found.
  LostSpace& ball = whole_lost_;
  ball.radius = whole_.result.lost_space_radius;
  ball.center = whole_.result.lost_space_center;
  const AABB box = part_.mesh.bounds();
  std::vector<std::string> cuts;
  std::vector<Mesh> children = cut_around(part_.mesh, box, ball, cuts);
  if (children.empty()) {
    whole_.result.reason += "; no cut leaves every piece dim_pre thick: not split";
    return std::move(whole_);
  }
  process_all(std::move(children), cuts, "", 1);
  std::string failure = failure_;
  if (failure.empty()) {
    // A ball across a cut fits in two pieces at once: the union is probed as a whole.
    std::vector<const AlphaSimSolid*> solids;
    for (const auto& leaf : leaves_) solids.push_back(leaf.solid.get());
    const LostSpace lost = probe_lost_space(solids, original_, box, r_lost_ / 2.0, opt_.lost_space_max_samples);
    if (lost.radius >= r_lost_) {
      failure = "their union hides a ball of radius " + full_precision(lost.radius) + " at " +
                full_precision(lost.center) + " across a cut";
    } else {
      whole_.result.lost_space_radius = lost.radius;
      whole_.result.lost_space_center = lost.center;
    }
  }
  AlphaSimPart out = assemble(failure);
  out.result.time_ms = whole_ms + t0.ms();
  return out;
}

}  // namespace

AlphaSimPart simplify_part_split(const Part& part, const AlphaSimOptions& opt, const std::string& step_stem) {
  AlphaSimPart whole = simplify_part(part, opt, step_stem);
  if (!opt.split_blocked || whole.result.status != AlphaSimStatus::Blocked) return whole;
  return PartSplitter(part, opt, std::move(whole)).run();
}

}  // namespace loom
