// `mpirun -np K loom audit`: loading, planning, part exchange and merge over MPI.
#include "app/audit_mpi.hpp"

#include "core/io/mesh_read.hpp"
#include "core/error.hpp"
#include "core/stopwatch.hpp"
#include "routing/audit/audit_shard.hpp"
#include "routing/audit/shard_plan.hpp"

#include <mpi.h>
#include <sys/resource.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <map>
#include <set>

namespace loom::app {

bool launched_by_mpi() {
  for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_SIZE"})
    if (std::getenv(v)) return true;
  return false;
}

MpiWorld::MpiWorld() {
  int provided = 0;
  MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
}

MpiWorld::~MpiWorld() { MPI_Finalize(); }

int MpiWorld::broadcast(int value) const {
  MPI_Bcast(&value, 1, MPI_INT, 0, MPI_COMM_WORLD);
  return value;
}

void MpiWorld::agree(bool failed, const std::string& message, bool input_error) const {
  int first = failed ? rank_ : size_;
  MPI_Allreduce(MPI_IN_PLACE, &first, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  if (first == size_) return;
  std::uint64_t n = message.size();
  int input = input_error ? 1 : 0;
  MPI_Bcast(&n, 1, MPI_UINT64_T, first, MPI_COMM_WORLD);
  MPI_Bcast(&input, 1, MPI_INT, first, MPI_COMM_WORLD);
  std::string text = message;
  text.resize(n);
  MPI_Bcast(text.data(), static_cast<int>(n), MPI_CHAR, first, MPI_COMM_WORLD);
  throw ShardFailure(first, text, input != 0);
}

namespace {

using Bytes = std::vector<std::uint8_t>;

/// Largest single MPI message: counts are ints, and smaller pieces keep buffers modest.
constexpr std::size_t kChunkBytes = std::size_t{1} << 30;

/// Sends `out` to rank `dst` while receiving from rank `src` (this rank's partners in a
/// pairwise round). The sizes go first in one MPI_Sendrecv; the bytes in pieces posted all
/// at once, so neither side waits for the other's pieces to pair with its own.
Bytes exchange(int dst, int src, const Bytes& out) {
  std::uint64_t n_out = out.size(), n_in = 0;
  MPI_Sendrecv(&n_out, 1, MPI_UINT64_T, dst, 1, &n_in, 1, MPI_UINT64_T, src, 1, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
  Bytes in(n_in);
  std::vector<MPI_Request> pending;
  for (std::size_t at = 0; at < n_in; at += kChunkBytes)
    MPI_Irecv(in.data() + at, static_cast<int>(std::min<std::size_t>(kChunkBytes, n_in - at)), MPI_BYTE, src, 2,
              MPI_COMM_WORLD, &pending.emplace_back());
  for (std::size_t at = 0; at < n_out; at += kChunkBytes)
    MPI_Isend(out.data() + at, static_cast<int>(std::min<std::size_t>(kChunkBytes, n_out - at)), MPI_BYTE, dst, 2,
              MPI_COMM_WORLD, &pending.emplace_back());
  MPI_Waitall(static_cast<int>(pending.size()), pending.data(), MPI_STATUSES_IGNORE);
  return in;
}

/// Every rank's `mine`, by rank (pairwise rounds of exchange()).
std::vector<Bytes> all_gather(const MpiWorld& mpi, const Bytes& mine) {
  std::vector<Bytes> all(static_cast<std::size_t>(mpi.size()));
  all[static_cast<std::size_t>(mpi.rank())] = mine;
  for (int step = 1; step < mpi.size(); ++step) {
    const int dst = (mpi.rank() + step) % mpi.size(), src = (mpi.rank() - step + mpi.size()) % mpi.size();
    all[static_cast<std::size_t>(src)] = exchange(dst, src, mine);
  }
  return all;
}

// ---- parts on the wire (fixed parts only: moving parts stay on rank 0) -----------------

template <class T>
void put(Bytes& b, const T& v) {
  const auto* p = reinterpret_cast<const std::uint8_t*>(&v);
  b.insert(b.end(), p, p + sizeof(T));
}
void put(Bytes& b, const std::string& s) {
  put(b, static_cast<std::uint64_t>(s.size()));
  b.insert(b.end(), s.begin(), s.end());
}

/// Reads what put() wrote, refusing to run past the end.
struct Reader {
  const Bytes& b;
  std::size_t at = 0;
  void need(std::size_t n) const {
    if (b.size() - at < n) throw std::runtime_error("truncated part data from another rank");
  }
  template <class T>
  T get() {
    need(sizeof(T));
    T v;
    std::memcpy(&v, b.data() + at, sizeof(T));
    at += sizeof(T);
    return v;
  }
  std::string str() {
    const auto n = get<std::uint64_t>();
    need(n);
    std::string s(b.begin() + static_cast<std::ptrdiff_t>(at), b.begin() + static_cast<std::ptrdiff_t>(at + n));
    at += n;
    return s;
  }
};

void put_part(Bytes& b, int global, const Part& p) {
  if (p.motion) throw std::logic_error("a moving part is never sent: it stays on rank 0");
  put(b, global);
  put(b, p.name), put(b, p.source_file), put(b, p.source_name);
  put(b, static_cast<int>(p.role)), put(b, p.clearance), put(b, p.closed), put(b, p.source_faces);
  put(b, p.voxel_edge), put(b, p.unknown_occupied);
  put(b, static_cast<std::uint64_t>(p.mesh.vertices.size()));
  for (const Vec3& v : p.mesh.vertices) put(b, v.x()), put(b, v.y()), put(b, v.z());
  put(b, static_cast<std::uint64_t>(p.mesh.triangles.size()));
  for (const auto& t : p.mesh.triangles) put(b, t);
}

std::pair<int, Part> get_part(Reader& r) {
  const int global = r.get<int>();
  Part p;
  p.name = r.str(), p.source_file = r.str(), p.source_name = r.str();
  p.role = static_cast<PartRole>(r.get<int>());
  p.clearance = r.get<double>(), p.closed = r.get<bool>(), p.source_faces = r.get<int>();
  p.voxel_edge = r.get<double>(), p.unknown_occupied = r.get<bool>();
  const auto nv = r.get<std::uint64_t>();
  r.need(nv * 3 * sizeof(double));
  p.mesh.vertices.reserve(nv);
  for (std::uint64_t i = 0; i < nv; ++i) {
    const double x = r.get<double>(), y = r.get<double>(), z = r.get<double>();
    p.mesh.vertices.emplace_back(x, y, z);
  }
  const auto nt = r.get<std::uint64_t>();
  r.need(nt * sizeof(std::array<std::uint32_t, 3>));
  p.mesh.triangles.reserve(nt);
  for (std::uint64_t i = 0; i < nt; ++i) p.mesh.triangles.push_back(r.get<std::array<std::uint32_t, 3>>());
  return {global, std::move(p)};
}

// ---- the part catalogue -------------------------------------------------------------

/// A loaded part as every rank learns of it.
struct PartRecord {
  int entry = 0;          ///< [[part]] entry in the file
  int within = 0;         ///< its place among the parts that entry yields
  int loader = 0;         ///< the rank that read its file
  std::string name;
  AABB box;
  std::size_t triangles = 0;
  bool keep_out = false;
  bool moving = false;
  double deflection = 0.0;  ///< CAD parts: the deflection it was meshed at (tessellation by need)
};

Bytes records_bytes(const std::vector<PartRecord>& rs, const std::vector<std::string>& notes) {
  nlohmann::json j = nlohmann::json::array();
  for (const PartRecord& r : rs)
    j.push_back({r.entry, r.within, r.loader, r.name, r.box.min.x(), r.box.min.y(), r.box.min.z(), r.box.max.x(),
                 r.box.max.y(), r.box.max.z(), r.triangles, r.keep_out, r.moving, r.deflection});
  return nlohmann::json::to_cbor(nlohmann::json{{"parts", j}, {"notes", notes}});
}

void read_records(const Bytes& b, std::vector<PartRecord>& rs, std::vector<std::string>& notes) {
  const nlohmann::json j = nlohmann::json::from_cbor(b);
  for (const auto& x : j.at("parts")) {
    PartRecord r;
    r.entry = x.at(0), r.within = x.at(1), r.loader = x.at(2), r.name = x.at(3);
    r.box.min = Vec3(x.at(4), x.at(5), x.at(6));
    r.box.max = Vec3(x.at(7), x.at(8), x.at(9));
    r.triangles = x.at(10), r.keep_out = x.at(11), r.moving = x.at(12), r.deflection = x.at(13);
    rs.push_back(r);
  }
  for (const auto& n : j.at("notes")) notes.push_back(n);
}

/// Which rank reads each [[part]] entry: moving parts on rank 0 (it owns them all), the
/// others largest file first to the rank with the fewest bytes so far.
std::vector<int> entry_loaders(const std::vector<Part>& entries, int ranks) {
  std::vector<int> loader(entries.size(), 0);
  std::vector<std::uintmax_t> bytes(static_cast<std::size_t>(ranks), 0), size(entries.size(), 0);
  std::vector<std::size_t> order;
  for (std::size_t e = 0; e < entries.size(); ++e) {
    std::error_code ec;
    const auto n = std::filesystem::file_size(entries[e].source_file, ec);
    size[e] = ec ? 0 : n;
    if (entries[e].motion) bytes[0] += size[e];
    else order.push_back(e);
  }
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return size[a] > size[b]; });
  for (const std::size_t e : order) {
    const auto r = static_cast<std::size_t>(std::min_element(bytes.begin(), bytes.end()) - bytes.begin());
    loader[e] = static_cast<int>(r);
    bytes[r] += size[e];
  }
  return loader;
}

/// A byte count as people read it (KiB, MiB or GiB, binary).
std::string human_bytes(double bytes) {
  const char* unit[] = {"KiB", "MiB", "GiB", "TiB"};
  int k = 0;
  double v = bytes / 1024.0;
  while (v >= 1024.0 && k < 3) v /= 1024.0, ++k;
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g %s", v, unit[k]);
  return buf;
}

/// Refuses a plan in which some rank would need more than `max_memory` bytes.
void check_memory(const ShardPlan& plan, double max_memory, const std::filesystem::path& scene_file) {
  if (!(max_memory > 0.0)) return;
  double total = 0.0;
  for (const std::size_t t : plan.region_triangles) total += static_cast<double>(t) * kRankBytesPerTriangle;
  for (std::size_t r = 0; r < plan.region_triangles.size(); ++r) {
    const double need = static_cast<double>(plan.region_triangles[r]) * kRankBytesPerTriangle;
    if (need <= max_memory) continue;
    const auto ranks = static_cast<long long>(std::ceil(total / max_memory));
    throw InputError({scene_file.string(), 0, "--max-memory"},
                     "rank " + std::to_string(r) + " would index " + std::to_string(plan.region_triangles[r]) +
                         " triangles, about " + human_bytes(need) + " (" + std::to_string(static_cast<int>(kRankBytesPerTriangle)) +
                         " bytes each), above " + human_bytes(max_memory) + "; the scene holds " + human_bytes(total) +
                         ": run it on at least " + std::to_string(std::max<long long>(ranks, 2)) +
                         " ranks of this size (more when parts are large)");
  }
}

/// What tessellation by need did on every rank, from the deflection each part was meshed
/// at (as refine_for_audit says it in one process).
TessellationByNeed by_need_summary(const Scene& scene, const std::vector<PartRecord>& parts) {
  TessellationByNeed t;
  t.used = scene.tessellation.by_need;
  if (!t.used) return t;
  t.fine_deflection = scene.tessellation.linear_deflection.value;
  t.coarse_deflection = scene.tessellation.coarse_deflection.value;
  for (std::size_t g = 0; g < parts.size(); ++g) {
    if (!(parts[g].deflection > 0.0)) continue;  // meshes and scans
    if (parts[g].deflection > t.fine_deflection * (1.0 + 1e-12)) ++t.coarse_parts;
    else if (t.coarse_deflection > t.fine_deflection) t.refined.push_back(static_cast<int>(g));
  }
  return t;
}

}  // namespace

ShardedAudit sharded_audit(const MpiWorld& mpi, const std::filesystem::path& scene_file, const AuditOptions& opt,
                           double max_memory) {
  const Stopwatch t0;
  ShardedAudit out;
  SceneLoadReport head_rep;
  // 1. The scene file and the harness, on every rank; the part entries without their files.
  mpi.collective([&] {
    SceneLoadOptions head;
    head.load_parts = false;
    out.scene = load_audit_scene(scene_file, opt, head, &head_rep);
  });
  const std::vector<int> loader = entry_loaders(out.scene.parts, mpi.size());
  // 2. This rank's share of the part files.
  std::vector<Part> loaded;
  std::vector<PartRecord> mine;
  std::vector<std::string> load_notes;
  mpi.collective([&] {
    SceneLoadOptions share;
    share.use_cache = true;
    for (std::size_t e = 0; e < loader.size(); ++e) share.entries.push_back(loader[e] == mpi.rank());
    share.tessellate_by_need = true;
    CadShapeStore cad_shapes;  // the coarse pass's transferred files, for the refinement
    share.cad_shapes = &cad_shapes;
    SceneLoadReport rep;
    Scene s = load_scene(scene_file, share, &rep);
    load_notes = rep.notes;
    s.harness = out.scene.harness;  // with --routes applied: tessellation by need follows the audited routes
    s.has_harness = out.scene.has_harness;
    refine_for_audit(s, opt, &cad_shapes);
    for (std::size_t k = 0; k < s.parts.size(); ++k) {
      const Part& p = s.parts[k];
      const int entry = rep.part_entries.at(k);
      const int within = k > 0 && rep.part_entries[k - 1] == entry ? mine.back().within + 1 : 0;
      mine.push_back({entry, within, mpi.rank(), p.name, p.mesh.bounds(), p.mesh.triangle_count(),
                      p.role == PartRole::KeepOut, p.motion.has_value(), p.deflection});
    }
    loaded = std::move(s.parts);
  });
  // 3. Every rank's parts, in the file's order (the order of one process), and the plan.
  std::vector<PartRecord> parts;
  std::vector<std::string> notes = head_rep.notes;
  for (const Bytes& b : all_gather(mpi, records_bytes(mine, load_notes))) read_records(b, parts, notes);
  std::stable_sort(parts.begin(), parts.end(), [](const PartRecord& a, const PartRecord& b) {
    return std::make_pair(a.entry, a.within) < std::make_pair(b.entry, b.within);
  });
  ShardPlan plan;
  mpi.collective([&] {
    std::set<std::string> names;
    for (const PartRecord& r : parts)
      if (!names.insert(r.name).second)
        throw InputError({scene_file.string(), 0, "part '" + r.name + "'"}, "duplicate part name '" + r.name + "'");
    std::vector<ShardPartBox> boxes;
    for (const PartRecord& r : parts) boxes.push_back({r.box, r.triangles, r.moving});
    std::vector<AuditCable> routed;
    const std::vector<CableInput> cables =
        out.scene.has_harness ? audit_cable_inputs(out.scene.harness, routed) : std::vector<CableInput>{};
    plan = plan_shards(boxes, cable_polylines(cables), mpi.size());
    check_memory(plan, max_memory, scene_file);
  });
  // 4. Parts to their owners: pairwise rounds, each rank sending what it read for the partner.
  std::map<std::pair<int, int>, int> global_of;  // (entry, within) → global id
  for (std::size_t g = 0; g < parts.size(); ++g) global_of[{parts[g].entry, parts[g].within}] = static_cast<int>(g);
  std::vector<std::pair<int, Part>> own;
  mpi.collective([&] {
    std::vector<Bytes> to(static_cast<std::size_t>(mpi.size()));
    for (std::size_t k = 0; k < loaded.size(); ++k) {
      const int g = global_of.at({mine[k].entry, mine[k].within});
      const int owner = plan.owner[static_cast<std::size_t>(g)];
      if (owner == mpi.rank()) own.emplace_back(g, std::move(loaded[k]));
      else put_part(to[static_cast<std::size_t>(owner)], g, loaded[k]), loaded[k] = Part{};
    }
    for (int step = 1; step < mpi.size(); ++step) {
      const int dst = (mpi.rank() + step) % mpi.size(), src = (mpi.rank() - step + mpi.size()) % mpi.size();
      const Bytes in = exchange(dst, src, to[static_cast<std::size_t>(dst)]);
      to[static_cast<std::size_t>(dst)] = Bytes{};
      Reader r{in};
      while (r.at < in.size()) own.push_back(get_part(r));
    }
  });
  loaded.clear();
  std::sort(own.begin(), own.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  // 5. This rank's audit of its own parts.
  AuditShard shard;
  shard.cable_passes = mpi.root();
  Scene scene = out.scene;
  scene.parts.clear();
  for (auto& [g, p] : own) shard.part_ids.push_back(g), scene.parts.push_back(std::move(p));
  own.clear();
  const double load_ms = t0.ms();
  AuditOptions shard_opt = opt;
  shard_opt.shard = &shard;
  if (!mpi.root()) shard_opt.progress = {}, shard_opt.check.progress = {};
  mpi.collective([&] {
    out.report = run_audit(scene, shard_opt);
    out.report.load_ms = load_ms;
  });
  // 6. The shard reports to rank 0, merged there, with each rank's peak memory.
  const Bytes mine_bytes = shard_report_bytes(out.report);
  long peak_kib = 0;
  {
    rusage use{};
    if (getrusage(RUSAGE_SELF, &use) == 0) peak_kib = use.ru_maxrss;  // KiB on Linux
  }
  std::vector<long> peaks(static_cast<std::size_t>(mpi.size()), 0);
  MPI_Gather(&peak_kib, 1, MPI_LONG, peaks.data(), 1, MPI_LONG, 0, MPI_COMM_WORLD);
  mpi.collective([&] {
    if (!mpi.root()) {
      exchange(0, 0, mine_bytes);
      return;
    }
    std::vector<AuditReport> reports;
    reports.push_back(std::move(out.report));
    for (int r = 1; r < mpi.size(); ++r) reports.push_back(shard_report_from_bytes(exchange(r, r, {})));
    for (int r = 0; r < mpi.size(); ++r) {
      const auto k = static_cast<std::size_t>(r);
      ShardSummary sum;
      sum.rank = r;
      sum.parts = static_cast<std::size_t>(std::count(plan.owner.begin(), plan.owner.end(), r));
      sum.triangles = plan.region_triangles[k];
      sum.estimated_bytes = static_cast<double>(sum.triangles) * kRankBytesPerTriangle;
      sum.peak_bytes = 1024.0 * static_cast<double>(peaks[k]);
      sum.load_ms = reports[k].load_ms, sum.index_ms = reports[k].index_ms, sum.check_ms = reports[k].check_ms;
      out.ranks.push_back(sum);
    }
    std::vector<ShardPart> catalogue;
    for (const PartRecord& p : parts) catalogue.push_back({p.name, p.keep_out, p.triangles});
    out.report = merge_audit_shards(std::move(reports), catalogue, out.scene.harness, out.scene.routing);
    out.report.tessellation = by_need_summary(out.scene, parts);
    if (out.report.tessellation.used) out.report.notes.push_back(tessellation_note(out.report.tessellation));
    // The load notes first, as one process says them; each note once.
    std::vector<std::string> merged;
    std::set<std::string> seen;
    for (const auto* list : {&notes, &out.report.notes})
      for (const std::string& n : *list)
        if (seen.insert(n).second) merged.push_back(n);
    out.report.notes = std::move(merged);
  });
  return out;
}

}  // namespace loom::app
