#pragma once
/// The bundle level of the certified audit (ClashRequest::per_cable false): the pieces the
/// cables are made of — their bend pieces (CableInput::bend_pieces: the harness segments each
/// runs through), or the whole curve of a cable without them — with the pieces equal in
/// content (one segment's curve, in either direction) found once, and the cables along each.
/// The checks of a piece are made once for all of its cables. Internal to the audit; world
/// frame, scene units; σ is arc length along a piece in its own direction, s along a cable.

#include "routing/audit/clash_context.hpp"

#include <string>
#include <utility>
#include <vector>

namespace loom::audit {

/// One cable running along a piece.
struct PieceUse {
  int cable = -1;
  double s0 = 0.0;        ///< cable arc length where it enters the piece
  double length = 0.0;    ///< the piece's length as the cable's own copy measures it
  bool reversed = false;  ///< the cable runs the piece against the piece's direction
  const Centerline* curve = nullptr;  ///< the cable's own copy of the piece, in its direction
  /// Cable arc length at piece arc length σ.
  double s_at(double sigma) const { return reversed ? s0 + (length - sigma) : s0 + sigma; }
};

/// A harness node that every cable along a piece has among its junctions (CableJunction).
struct PieceJunction {
  int node = -1;  ///< index into Layout::nodes
  Vec3 position = Vec3::Zero();
  double radius = 0.0;  ///< the smallest radius any of the cables gives it
};

/// A curve that one or more cables run along.
struct Piece {
  const Centerline* curve = nullptr;  ///< the first use's copy (its direction is the piece's)
  double length = 0.0;                ///< arc length of `curve`
  std::vector<PieceUse> uses;         ///< by radius, largest first (ties: by cable)
  double r_max = 0.0, r_min = 0.0;    ///< largest and smallest radius of its cables
  /// A harness segment that every cable along the piece lists over all of it, with both of
  /// the piece's ends at junctions of all of them at least 2·r_max wide: any two of its
  /// cables are excused wherever both run on it (bundled). −1 if there is none.
  int bundle_segment = -1;
  std::vector<PieceJunction> junctions;  ///< the nodes common to all its cables, by node
};

/// The pieces of every cable.
struct Layout {
  std::vector<Piece> pieces;
  std::vector<std::string> nodes;  ///< junction node ids (PieceJunction::node)
  /// Per cable: (piece, index into its uses) of each piece it runs along, in order along it.
  std::vector<std::vector<std::pair<int, int>>> of_cable;
  bool shared = false;  ///< some piece carries more than one cable
};

/// The layout of `cables`. A cable's bend pieces are its pieces where they follow each other
/// from s = 0 to its end (within 10⁻⁶ of its length) and its curve starts and ends where
/// they do (within `meet`, scene units); otherwise its whole curve is its one piece (bend
/// pieces are the curve's own pieces: CableInput). Pieces
/// are one when their control points are equal in one order or the other and their knots
/// equal up to an affine map (10⁻⁹ of their range): the same curve. A cable never shares a
/// piece with itself (a route over one curve twice keeps two pieces).
Layout make_layout(const std::vector<CableInput>& cables, double meet, int threads);

/// A stretch of a shared piece measured once for all its cables.
struct MeasuredRun {
  double sigma0 = 0.0, sigma1 = 0.0;       ///< along the piece
  std::vector<MeasuredChord> chords;       ///< in the piece's direction
  std::vector<std::pair<int, double>> nearest;  ///< per part reached: its smallest distance
};

/// The bundle level's structure work: what it measured (read by the cables' passes through
/// their hints) and one StructureHints per cable.
struct BundleStructure {
  std::vector<std::vector<MeasuredRun>> measured;  ///< per piece
  std::vector<StructureHints> cables;              ///< per cable
};

/// The structure work of every piece carrying more than one cable, once as a tube of its
/// largest radius r_max: a sphere trace (Lipschitz bisection, free-space queries as
/// ClashRequest::distance_rel_error allows) proves stretches farther than r_max + band +
/// margin from every part, outside every closed part (one inside test per stretch); the
/// rest is flattened into chords (at most 2·r_min, within the chord error) measured
/// exactly against every part whose box comes within reach — unless a chord touches a
/// surface or the stretch starts inside a closed part, where the inside of parts can change
/// and the cables trace it themselves. A cable attached to a part (PartAttachment) over a
/// measured stretch traces that stretch itself too. Each cable's hints hold its stretches
/// so decided, in its arc length, and the smallest clearance seen on them.
BundleStructure bundle_structure(Context& ctx, const Layout& lay);

/// The certified cable–cable and self pass at the bundle level: the same contacts as
/// certified_cable_pairs() within the tolerance, one entry per contact stretch appended to
/// `out`. Pieces are flattened once (chords of at most 2·r_min, within the chord error),
/// their blocks go through one broad phase, each chord pair is measured once; the pair
/// rules (judge_chord_pair) run per cable pair only where the pair's radii reach past the
/// excuse of the junctions all cables of both pieces share, and per self class (cables of
/// one radius and one arc-length offset between the pieces) only where its first member
/// has a contact. Two cables of a piece with a bundle segment never cost a test.
void bundle_cable_pairs(Context& ctx, const Layout& lay, std::vector<ClashEntry>& out);

/// Bend results of the curves cables share bit for bit (one piece run the same way):
/// computed once per curve, and once per bend limit of its cables.
class BendMemo {
 public:
  /// Computes them for every piece of `lay` (in parallel) that is a bend piece of its
  /// cables (or, for a cable without bend pieces, its curve).
  BendMemo(const Context& ctx, const Layout& lay);
  /// The smallest bend radius of cable c's k-th bend piece (its curve when it has none), or
  /// null when it was not computed here.
  const BendExtremum* min_radius(std::size_t c, std::size_t k) const;
  /// Its stretches bending tighter than the cable's min_bend_radius, or null when they
  /// were not computed here (none are when the limit is not above the smallest radius).
  const std::vector<BendExtremum>* below(std::size_t c, std::size_t k) const;

 private:
  struct Group {
    const Centerline* curve = nullptr;
    BendExtremum min;
    std::vector<std::pair<double, std::vector<BendExtremum>>> below;  ///< per limit
  };
  std::vector<Group> groups_;
  std::vector<std::vector<int>> of_cable_;  ///< per cable, per bend piece: its group (−1: none)
  const std::vector<CableInput>& cables_;
};

}  // namespace loom::audit
