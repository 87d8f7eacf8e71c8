#include "core/io/tessellation_cache.hpp"

#include "core/io/atomic_file.hpp"
#include "core/io/input_file.hpp"

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>

namespace loom {

namespace {
/// Format and naming version of an entry. 02: repeated product names get the first free "#k"
/// (01 could give two pieces one name, which the scene then refused; such entries are misses).
/// 03: each mesh keeps its leaf index (tessellation by need re-meshes one leaf).
constexpr char kMagic[8] = {'L', 'O', 'O', 'M', 'T', 'C', '0', '3'};

std::uint64_t fnv1a(const void* data, std::size_t n, std::uint64_t h = 1469598103934665603ull) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 1099511628211ull;
  return h;
}

template <typename T>
void put(std::ostream& os, const T& v) {
  os.write(reinterpret_cast<const char*>(&v), sizeof(T));
}
template <typename T>
bool get(std::istream& is, T& v) {
  return static_cast<bool>(is.read(reinterpret_cast<char*>(&v), sizeof(T)));
}

bool load(const std::filesystem::path& f, std::vector<NamedMesh>& out) {
  std::error_code ec;
  const std::uint64_t size = std::filesystem::file_size(f, ec);
  if (ec) return false;
  std::ifstream in(f, std::ios::binary);
  if (!in) return false;
  char magic[8];
  if (!in.read(magic, 8) || std::memcmp(magic, kMagic, 8) != 0) return false;
  std::uint64_t n;
  if (!get(in, n) || n > (1u << 24)) return false;
  out.clear();
  for (std::uint64_t i = 0; i < n; ++i) {
    NamedMesh nm;
    std::uint64_t len, nv, nt;
    std::int32_t faces, leaf;
    if (!get(in, len) || len > 4096) return false;
    nm.name.resize(len);
    if (!in.read(nm.name.data(), static_cast<std::streamsize>(len))) return false;
    if (!get(in, faces) || !get(in, leaf) || !get(in, nv) || !get(in, nt) || nv > (1ull << 32) ||
        nt > (1ull << 32))
      return false;
    // A corrupt or truncated entry must not size the arrays (2^32 vertices: 96 GB, then
    // std::bad_alloc on every run until the cache was deleted): the rest of the file bounds them.
    const auto at = in.tellg();
    if (at < 0) return false;
    const std::uint64_t left = size - std::min<std::uint64_t>(size, static_cast<std::uint64_t>(at));
    const std::uint64_t tri_bytes = sizeof(nm.mesh.triangles[0]);
    if (nv > left / sizeof(Vec3) || nt > (left - nv * sizeof(Vec3)) / tri_bytes) return false;
    nm.brep_faces = faces;
    nm.leaf = leaf;
    nm.mesh.vertices.resize(nv);
    nm.mesh.triangles.resize(nt);
    if (!in.read(reinterpret_cast<char*>(nm.mesh.vertices.data()), static_cast<std::streamsize>(nv * sizeof(Vec3))))
      return false;
    if (!in.read(reinterpret_cast<char*>(nm.mesh.triangles.data()),
                 static_cast<std::streamsize>(nt * sizeof(nm.mesh.triangles[0]))))
      return false;
    for (const auto& t : nm.mesh.triangles)
      for (auto v : t)
        if (v >= nv) return false;
    out.push_back(std::move(nm));
  }
  return true;
}

void store(const std::filesystem::path& f, const std::vector<NamedMesh>& meshes) {
  try {
    AtomicFile af(f, true);
    auto& os = af.stream();
    os.write(kMagic, 8);
    put<std::uint64_t>(os, meshes.size());
    for (const auto& nm : meshes) {
      put<std::uint64_t>(os, nm.name.size());
      os.write(nm.name.data(), static_cast<std::streamsize>(nm.name.size()));
      put<std::int32_t>(os, nm.brep_faces);
      put<std::int32_t>(os, nm.leaf);
      put<std::uint64_t>(os, nm.mesh.vertices.size());
      put<std::uint64_t>(os, nm.mesh.triangles.size());
      os.write(reinterpret_cast<const char*>(nm.mesh.vertices.data()),
               static_cast<std::streamsize>(nm.mesh.vertices.size() * sizeof(Vec3)));
      os.write(reinterpret_cast<const char*>(nm.mesh.triangles.data()),
               static_cast<std::streamsize>(nm.mesh.triangles.size() * sizeof(nm.mesh.triangles[0])));
    }
    af.commit();
  } catch (const std::exception&) {
    // An unwritable cache only costs time on the next run; the result is already in hand.
  }
}
}  // namespace

std::filesystem::path tessellation_cache_dir() {
  if (const char* d = std::getenv("LOOM_CACHE_DIR"); d && *d) return d;
  if (const char* d = std::getenv("XDG_CACHE_HOME"); d && *d) return std::filesystem::path(d) / "loom";
  if (const char* d = std::getenv("HOME"); d && *d) return std::filesystem::path(d) / ".cache" / "loom";
  return {};
}

std::string tessellation_cache_key(const std::filesystem::path& file, const TessellationParams& tp, bool split,
                                   const std::vector<int>* only_leaves) {
  std::ifstream in(file, std::ios::binary);
  std::uint64_t h = 1469598103934665603ull;
  char buf[1 << 16];
  while (in.read(buf, sizeof buf) || in.gcount() > 0) h = fnv1a(buf, static_cast<std::size_t>(in.gcount()), h);
  const double params[3] = {tp.linear_deflection, tp.angular_deflection_deg, tp.unit_in_mm};
  h = fnv1a(params, sizeof params, h);
  const unsigned char s = split ? 1 : 0;
  h = fnv1a(&s, 1, h);
  if (only_leaves) {
    const std::uint64_t n = only_leaves->size();
    h = fnv1a(&n, sizeof n, h);
    h = fnv1a(only_leaves->data(), only_leaves->size() * sizeof(int), h);
  }
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h));
  return hex;
}

std::vector<NamedMesh> read_cad_file_cached(const std::filesystem::path& path, const TessellationParams& tp,
                                            bool split, bool* hit, const std::vector<int>* only_leaves,
                                            CadShapeStore* shapes) {
  // Before the key hashes its bytes: a FIFO never gives any, a device such as /dev/zero never ends.
  require_input_file(path, "file");
  const auto dir = tessellation_cache_dir();
  std::vector<NamedMesh> out;
  if (dir.empty()) {
    if (hit) *hit = false;
    return read_cad_file(path, tp, split, only_leaves, shapes);
  }
  const auto f = dir / (tessellation_cache_key(path, tp, split, only_leaves) + ".tess");
  if (load(f, out)) {
    if (hit) *hit = true;
    return out;
  }
  out = read_cad_file(path, tp, split, only_leaves, shapes);
  store(f, out);
  if (hit) *hit = false;
  return out;
}

}  // namespace loom
