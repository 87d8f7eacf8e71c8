#pragma once
/// The certified audit's bookkeeping along one cable (clash_check): observations of parts
/// within their clearance band, in arc-length order, grouped into one clash per contiguous
/// contact stretch (at its deepest point) and one clearance violation per band stretch
/// without contact. Internal to the audit (namespace loom::audit; used by the certified and the
/// discrete cable–structure passes); world frame, scene units.

#include "routing/audit/clash_check.hpp"

#include <functional>
#include <limits>
#include <map>
#include <optional>
#include <vector>

namespace loom::audit {

/// What the checker needs to know about one part.
struct PartInfo {
  AABB box;
  double required = 0.0;  ///< routing clearance + part clearance
  bool keep_out = false;
  bool closed = false;
};

/// A chord whose distance to one part is known only within bounds: measured exactly only if
/// it can be the deepest point of its stretch (StretchTracker resolves it at the close).
struct DeferredChord {
  Vec3 a = Vec3::Zero(), b = Vec3::Zero();  ///< chord ends
  double s0 = 0.0, s1 = 0.0;                ///< arc lengths at the ends
};

/// One observation of a part along the centerline.
struct PartObservation {
  int part = -1;
  /// Clearance, and −r − depth when the axis is inside (ranking).
  double key = std::numeric_limits<double>::infinity();
  /// While `deferred`: key is the clearance at a surface point found (an upper bound) and
  /// the exact key lies in [key_lower, key]. Unused otherwise.
  double key_lower = std::numeric_limits<double>::infinity();
  Vec3 point = Vec3::Zero();
  double s = 0.0;
  bool inside = false;
  std::optional<DeferredChord> deferred;
};

/// Replaces a deferred observation's bounds by the exact key, point and arc length.
using ObservationResolver = std::function<void(PartObservation&)>;

/// True if the cable is attached to `part` at arc length s (see PartAttachment); for an
/// observation of the centerline inside the part (`inside`), only where the part holds the
/// port (holds_port at `tolerance`).
bool is_attached(const std::vector<PartAttachment>& attachments, int part, double s, bool inside = false,
                 double tolerance = 0.0);

/// Collects observations in s order. A part's band stretch (clearance < required) ends
/// when a step no longer sees it; inside it, each contiguous contact stretch (clearance < 0)
/// becomes one clash at its deepest point, and a band stretch without contact becomes one
/// clearance violation at its smallest clearance. A deferred observation's bounds must
/// already decide the band and contact (its key and key_lower on one side of required and
/// of 0); when its stretch closes it is resolved (measured exactly) only if its lower bound
/// reaches the stretch's smallest upper bound — only then can it be the deepest.
class StretchTracker {
 public:
  /// `resolve` measures deferred observations (may be empty if none are ever stepped);
  /// `tolerance` is the audit's (scene units), for holds_port.
  StretchTracker(int cable, double radius, const std::vector<PartInfo>& parts,
                 const std::vector<PartAttachment>& attachments, ObservationResolver resolve = {},
                 double tolerance = 0.0)
      : cable_(cable),
        radius_(radius),
        tolerance_(tolerance),
        parts_(parts),
        attachments_(attachments),
        resolve_(std::move(resolve)) {}

  /// One step along the cable (a chord, a sample or a free interval) seeing `obs` (parts
  /// within their band), spanning arc lengths [s0, s1]. Observations of a part the cable
  /// is attached to, within the attachment's range, are not findings and are dropped.
  void step(const std::vector<PartObservation>& all, double s0, double s1);
  /// Closes every open stretch (end of the cable or of a proven-clear gap).
  void flush();
  std::vector<ClashEntry> clashes;
  std::vector<Violation> violations;
  double min_key = std::numeric_limits<double>::infinity();  ///< smallest key seen in any band (exact: deferred ones resolved)

 private:
  struct Stretch {
    PartObservation deepest;  ///< smallest key: an upper bound while it is deferred
    PartObservation exact;    ///< smallest key among the observations measured exactly
    double s_begin = 0.0, s_end = 0.0;
    void take(const PartObservation& o) {
      if (o.key < deepest.key) deepest = o;
      if (!o.deferred && o.key < exact.key) exact = o;
    }
    /// After settle(): a measured observation that may be deeper than `exact`; among
    /// equal keys the one first along the cable, as when all are measured in order.
    void fold(const PartObservation& o) {
      if (o.key < exact.key || (o.key == exact.key && o.s < exact.s)) exact = o;
    }
  };
  struct Candidate {
    PartObservation obs;
    int contact = -1;  ///< index into Open::contacts, −1 outside a contact stretch
  };
  struct Open {
    bool started = false;
    Stretch band;
    std::vector<Stretch> contacts;
    bool contact_open = false;
    std::vector<Candidate> candidates;  ///< deferred observations that may be a deepest
  };
  /// Measures the deferred observations that can still be the deepest of their band or
  /// contact stretch and takes the deepest again. An observation left unmeasured has a
  /// lower bound above a measured key, so the deepest (and its first occurrence among
  /// equal keys) is the one exact keys everywhere would give.
  void settle(Open& st);
  /// Settles a band stretch, then writes its contact stretches as clashes (each at its
  /// deepest point) or, without contact, its smallest clearance as a violation.
  void close(Open& st);
  int cable_;
  double radius_;
  double tolerance_;
  const std::vector<PartInfo>& parts_;
  const std::vector<PartAttachment>& attachments_;
  ObservationResolver resolve_;
  std::vector<PartObservation> kept_;  ///< observations of one step minus attached parts
  std::map<int, Open> open_;
};

}  // namespace loom::audit
