#include "core/io/mesh_write.hpp"

#include "core/error.hpp"
#include "core/io/atomic_file.hpp"

#include <algorithm>
#include <cctype>
#include <cstring>

namespace loom {

MeshFormat mesh_format_for(const std::filesystem::path& p) {
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  if (ext == ".stl") return MeshFormat::Stl;
  if (ext == ".ply") return MeshFormat::Ply;
  if (ext == ".obj") return MeshFormat::Obj;
  throw InputError({p.string(), 0, ""}, "unknown mesh output extension '" + ext + "' (use .stl, .ply or .obj)");
}

namespace {
template <typename T>
void put(std::ostream& os, T v) {
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  os.write(b, sizeof(T));
}

void write_stl(std::ostream& os, const Mesh& m) {
  char header[80] = {};
  std::snprintf(header, sizeof header, "loom binary STL");
  os.write(header, 80);
  put<std::uint32_t>(os, static_cast<std::uint32_t>(m.triangles.size()));
  for (std::size_t t = 0; t < m.triangles.size(); ++t) {
    const auto c = m.corners(t);
    Vec3 n = (c[1] - c[0]).cross(c[2] - c[0]);
    const double len = n.norm();
    if (len > 0) n /= len;
    for (int k = 0; k < 3; ++k) put<float>(os, static_cast<float>(n[k]));
    for (const auto& v : c)
      for (int k = 0; k < 3; ++k) put<float>(os, static_cast<float>(v[k]));
    put<std::uint16_t>(os, 0);
  }
}

void write_ply(std::ostream& os, const Mesh& m, const std::vector<std::array<std::uint8_t, 3>>& colors) {
  const bool rgb = colors.size() == m.vertices.size() && !colors.empty();
  os << "ply\nformat binary_little_endian 1.0\ncomment written by loom\n"
     << "element vertex " << m.vertices.size() << "\nproperty double x\nproperty double y\nproperty double z\n";
  if (rgb) os << "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  os << "element face " << m.triangles.size() << "\nproperty list uchar uint vertex_indices\nend_header\n";
  for (std::size_t i = 0; i < m.vertices.size(); ++i) {
    for (int k = 0; k < 3; ++k) put<double>(os, m.vertices[i][k]);
    if (rgb)
      for (int k = 0; k < 3; ++k) put<std::uint8_t>(os, colors[i][k]);
  }
  for (const auto& f : m.triangles) {
    put<std::uint8_t>(os, 3);
    for (auto i : f) put<std::uint32_t>(os, i);
  }
}

void write_obj(std::ostream& os, const Mesh& m) {
  os << "# written by loom\n";
  os.precision(17);
  for (const auto& v : m.vertices) os << "v " << v.x() << ' ' << v.y() << ' ' << v.z() << '\n';
  for (const auto& f : m.triangles) os << "f " << f[0] + 1 << ' ' << f[1] + 1 << ' ' << f[2] + 1 << '\n';
}
}  // namespace

void write_mesh(const std::filesystem::path& path, const Mesh& mesh,
                const std::vector<std::array<std::uint8_t, 3>>& colors) {
  const MeshFormat fmt = mesh_format_for(path);
  AtomicFile f(path, true);
  switch (fmt) {
    case MeshFormat::Stl: write_stl(f.stream(), mesh); break;
    case MeshFormat::Ply: write_ply(f.stream(), mesh, colors); break;
    case MeshFormat::Obj: write_obj(f.stream(), mesh); break;
  }
  f.commit();
}

}  // namespace loom
