#pragma once
/// `mpirun -np K loom audit SCENE`: the audit sharded over the ranks of MPI_COMM_WORLD
/// (docs/audit.md "Sharding"). Each rank reads the scene file and the harness, loads a
/// share of the part files (moving parts on rank 0, the rest balanced by file size) and
/// tells the others their boxes and triangle counts; plan_shards divides space among the
/// ranks; a part loaded on one rank and owned by another is sent to its owner; each rank
/// indexes and checks its own parts; rank 0 merges the shard reports (merge_audit_shards).
/// A rank that fails stops every rank at the next step with its rank, file and reason.

#include "core/error.hpp"
#include "routing/audit/audit.hpp"

#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

namespace loom::app {

/// True when this process was started by an MPI launcher (Open MPI's mpirun, or any
/// launcher that sets PMI/PMIx variables): `loom audit` then runs as one rank.
bool launched_by_mpi();

/// MPI_Init_thread on construction (funneled: only the calling thread talks MPI),
/// MPI_Finalize on destruction.
class MpiWorld {
 public:
  MpiWorld();
  ~MpiWorld();
  MpiWorld(const MpiWorld&) = delete;
  MpiWorld& operator=(const MpiWorld&) = delete;
  int rank() const { return rank_; }
  int size() const { return size_; }
  bool root() const { return rank_ == 0; }
  /// Runs `fn` on this rank, then agrees with every rank on the outcome: if any rank threw,
  /// every rank throws ShardFailure carrying the lowest failing rank and its message.
  template <class F>
  void collective(F&& fn) const;
  /// The value of rank 0, on every rank.
  int broadcast(int value) const;

 private:
  void agree(bool failed, const std::string& message, bool input_error) const;
  int rank_ = 0, size_ = 1;
};

/// A step of the sharded audit failed on some rank (the same on every rank).
class ShardFailure : public std::runtime_error {
 public:
  ShardFailure(int rank, const std::string& message, bool input_error)
      : std::runtime_error("rank " + std::to_string(rank) + ": " + message), input_error_(input_error) {}
  /// The failing rank threw InputError (bad input: exit 2), not another error.
  bool input_error() const { return input_error_; }

 private:
  bool input_error_;
};

/// Bytes of memory one rank needs per triangle it owns: the Embree index (128 B measured
/// at 10⁶–5·10⁶ triangles, bench/results/index_build.csv) and the mesh itself (≈ 24 B:
/// double vertices shared by about two triangles, three 32-bit indices), rounded up.
constexpr double kRankBytesPerTriangle = 160.0;

/// One rank's share of a sharded audit (report.json "shards").
struct ShardSummary {
  int rank = 0;
  std::size_t parts = 0;         ///< parts it owned
  std::size_t triangles = 0;     ///< their triangles
  double estimated_bytes = 0.0;  ///< triangles × kRankBytesPerTriangle
  double peak_bytes = 0.0;       ///< the process's peak resident memory (getrusage)
  double load_ms = 0.0, index_ms = 0.0, check_ms = 0.0;
};

/// What a rank knows when the sharded audit is done.
struct ShardedAudit {
  AuditReport report;  ///< rank 0: the merged report; other ranks: their own shard's
  Scene scene;         ///< the audited scene's settings and harness, without parts
  std::vector<ShardSummary> ranks;  ///< rank 0: one per rank
};

/// Runs the audit of `scene_file` sharded over the ranks of MPI_COMM_WORLD (every rank calls it
/// with the same arguments). `max_memory` > 0: refuse, before any index is built, a plan
/// in which some rank would need more bytes than that (kRankBytesPerTriangle), naming
/// the rank, the figure and the ranks the scene needs. Throws ShardFailure.
ShardedAudit sharded_audit(const MpiWorld& mpi, const std::filesystem::path& scene_file, const AuditOptions& opt,
                           double max_memory);

template <class F>
void MpiWorld::collective(F&& fn) const {
  std::string message;
  bool failed = false, input = false;
  try {
    fn();
  } catch (const InputError& e) {
    failed = true, input = true, message = e.what();
  } catch (const std::bad_alloc&) {
    failed = true, message = "out of memory";
  } catch (const std::exception& e) {
    failed = true, message = e.what();
  }
  agree(failed, message, input);
}

}  // namespace loom::app
