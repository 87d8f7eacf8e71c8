#include "routing/view/render.hpp"

#include "core/stopwatch.hpp"
#include "core/error.hpp"
#include "core/harness_topology.hpp"
#include "core/io/atomic_file.hpp"
#include "index/embree_index.hpp"
#include "routing/curve/cable_geometry.hpp"
#include "routing/audit/report_json.hpp"
#include "routing/curve/sweep.hpp"

#include <png.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <set>
#include <string>
#include <vector>

namespace loom {

namespace {

constexpr std::array<std::uint8_t, 3> kBackground{244, 245, 247};
constexpr std::array<std::uint8_t, 3> kStructure{163, 173, 184};
constexpr std::array<std::uint8_t, 3> kKeepOut{208, 112, 112};
constexpr std::array<std::uint8_t, 3> kClash{224, 32, 32};
constexpr std::array<std::uint8_t, 3> kBend{255, 140, 0};
constexpr std::array<std::uint8_t, 3> kClearance{224, 192, 0};
constexpr std::array<std::uint8_t, 3> kOutline{40, 20, 20};
constexpr std::array<std::uint8_t, 3> kClamp{0, 144, 168};
/// Lambert shading: ambient share and the light's share of the base colour.
constexpr double kAmbient = 0.3;
constexpr double kDiffuse = 0.7;
/// The light sits above the camera: its direction is −ray + this × camera up.
constexpr double kLightLift = 0.5;
/// Tube mesh resolution: chord tolerance as a fraction of the cable radius.
constexpr double kTubeChordPerRadius = 0.1;
/// Most pixels on a side (a larger request is bad input, not a picture).
constexpr int kMaxSide = 16384;
/// Viewing direction (from the target towards the eye) of the framing camera, the same as view.html's.
const Vec3 kViewFrom = Vec3(1.0, -1.4, 0.9).normalized();
/// The framing camera leaves this share of margin around the framed box.
constexpr double kFrameMargin = 1.08;

struct Basis {
  Vec3 f, r, u;
  double tan_half, aspect;
};

Basis basis_of(const RenderCamera& cam, int width, int height) {
  Basis b;
  b.f = (cam.target - cam.eye).normalized();
  b.r = b.f.cross(cam.up);
  if (b.r.norm() < 1e-12) b.r = b.f.cross(std::abs(b.f.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY());
  b.r.normalize();
  b.u = b.r.cross(b.f);
  b.tan_half = std::tan(0.5 * cam.fov_deg * M_PI / 180.0);
  b.aspect = static_cast<double>(width) / static_cast<double>(height);
  return b;
}

std::array<std::uint8_t, 3> shade(const std::array<std::uint8_t, 3>& base, double k) {
  std::array<std::uint8_t, 3> c{};
  for (int i = 0; i < 3; ++i)
    c[static_cast<std::size_t>(i)] =
        static_cast<std::uint8_t>(std::clamp(std::lround(base[static_cast<std::size_t>(i)] * k), 0L, 255L));
  return c;
}

void put(Image& img, int x, int y, const std::array<std::uint8_t, 3>& c) {
  if (x < 0 || y < 0 || x >= img.width || y >= img.height) return;
  const std::size_t o = (static_cast<std::size_t>(y) * static_cast<std::size_t>(img.width) + static_cast<std::size_t>(x)) * 3;
  img.rgb[o] = c[0];
  img.rgb[o + 1] = c[1];
  img.rgb[o + 2] = c[2];
}

void disc(Image& img, const Eigen::Vector2d& p, double r, const std::array<std::uint8_t, 3>& c) {
  const double ro = r + 1.5;  // a dark ring keeps the disc visible on any colour
  for (int y = static_cast<int>(std::floor(p.y() - ro)); y <= static_cast<int>(std::ceil(p.y() + ro)); ++y)
    for (int x = static_cast<int>(std::floor(p.x() - ro)); x <= static_cast<int>(std::ceil(p.x() + ro)); ++x) {
      const double d = std::hypot(x + 0.5 - p.x(), y + 0.5 - p.y());
      if (d <= r) put(img, x, y, c);
      else if (d <= ro) put(img, x, y, kOutline);
    }
}

std::optional<Vec3> point_of(const nlohmann::json& e) {
  if (!e.is_object() || !e.contains("point") || !e["point"].is_array() || e["point"].size() != 3) return std::nullopt;
  Vec3 p;
  for (int k = 0; k < 3; ++k) {
    const auto& v = e["point"][static_cast<std::size_t>(k)];
    if (!v.is_number()) return std::nullopt;
    p[k] = v.get<double>();
  }
  return p.allFinite() ? std::optional<Vec3>(p) : std::nullopt;
}

std::string png_bytes(const Image& img) {
  std::string out;
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  if (!png) throw std::runtime_error("libpng: cannot create a write struct");
  png_infop info = png_create_info_struct(png);
  if (!info || setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    throw std::runtime_error("libpng: encoding failed");
  }
  png_set_write_fn(
      png, &out,
      [](png_structp p, png_bytep data, png_size_t n) {
        static_cast<std::string*>(png_get_io_ptr(p))->append(reinterpret_cast<const char*>(data), n);
      },
      [](png_structp) {});
  png_set_IHDR(png, info, static_cast<png_uint_32>(img.width), static_cast<png_uint_32>(img.height), 8,
               PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  for (int y = 0; y < img.height; ++y)
    png_write_row(png, const_cast<png_bytep>(img.rgb.data() + static_cast<std::size_t>(y) * img.width * 3));
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return out;
}

/// Most cable points the camera choice looks at (tube vertices, evenly subsampled).
constexpr std::size_t kVisibilitySamples = 2048;
/// Share of a cable's colour seen through the structure that hides it.
constexpr double kSeeThrough = 0.45;

/// The eight viewing directions (target → eye) of the framing camera: the default first,
/// then its mirror images through the axis planes.
std::vector<Vec3> view_candidates() {
  std::vector<Vec3> out;
  for (double sz : {1.0, -1.0})
    for (double sy : {1.0, -1.0})
      for (double sx : {1.0, -1.0}) out.push_back(Vec3(sx * kViewFrom.x(), sy * kViewFrom.y(), sz * kViewFrom.z()));
  return out;
}

/// The framing camera from whichever candidate direction sees the most of `points` (cable
/// tube vertices) unhidden by the parts; ties keep the earlier candidate. `visible` gets
/// the chosen camera's share of unhidden points.
RenderCamera least_hidden_camera(const AABB& box, double aspect, const EmbreeIndex* parts,
                                 const std::vector<Vec3>& points, double& visible) {
  RenderCamera best = frame_camera(box, aspect);
  visible = 1.0;
  if (!parts || points.empty()) return best;
  const std::size_t stride = std::max<std::size_t>(1, points.size() / kVisibilitySamples);
  std::size_t best_seen = 0, looked = 0;
  bool first = true;
  for (const Vec3& from : view_candidates()) {
    const RenderCamera cam = frame_camera(box, aspect, from);
    std::size_t seen = 0;
    looked = 0;
    for (std::size_t i = 0; i < points.size(); i += stride, ++looked)
      seen += !parts->ray(points[i], cam.eye - points[i], 1.0).found();
    if (first || seen > best_seen) {
      best = cam;
      best_seen = seen;
      first = false;
    }
  }
  visible = looked ? static_cast<double>(best_seen) / static_cast<double>(looked) : 1.0;
  return best;
}

}  // namespace

std::array<std::uint8_t, 3> Image::at(int x, int y) const {
  const std::size_t o = (static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x)) * 3;
  return {rgb[o], rgb[o + 1], rgb[o + 2]};
}

std::array<std::uint8_t, 3> cable_colour(std::size_t i) {
  // hsl(i × 137.508°, 70 %, 45 %), as view.html colours cable i.
  const double h = std::fmod(static_cast<double>(i) * 137.508, 360.0) / 60.0, s = 0.7, l = 0.45;
  const double c = (1 - std::abs(2 * l - 1)) * s, x = c * (1 - std::abs(std::fmod(h, 2.0) - 1)), m = l - c / 2;
  double r = 0, g = 0, b = 0;
  switch (static_cast<int>(h)) {
    case 0: r = c; g = x; break;
    case 1: r = x; g = c; break;
    case 2: g = c; b = x; break;
    case 3: g = x; b = c; break;
    case 4: r = x; b = c; break;
    default: r = c; b = x; break;
  }
  auto to8 = [&](double v) { return static_cast<std::uint8_t>(std::clamp(std::lround((v + m) * 255.0), 0L, 255L)); };
  return {to8(r), to8(g), to8(b)};
}

RenderCamera frame_camera(const AABB& box, double aspect) { return frame_camera(box, aspect, kViewFrom); }

RenderCamera frame_camera(const AABB& box, double aspect, const Vec3& view_from) {
  RenderCamera cam;
  const Vec3 c = box.center();
  const double radius = std::max(0.5 * box.size().norm(), 1e-9);
  const double half_v = 0.5 * cam.fov_deg * M_PI / 180.0;
  const double half_h = std::atan(std::tan(half_v) * aspect);
  const double dist = kFrameMargin * radius / std::sin(std::min(half_v, half_h));
  cam.target = c;
  cam.eye = c + view_from.normalized() * dist;
  return cam;
}

std::optional<Eigen::Vector2d> project_to_pixel(const RenderCamera& cam, int width, int height, const Vec3& p) {
  const Basis b = basis_of(cam, width, height);
  const Vec3 d = p - cam.eye;
  const double z = d.dot(b.f);
  if (!(z > 0.0)) return std::nullopt;
  const double nx = d.dot(b.r) / z / (b.tan_half * b.aspect), ny = d.dot(b.u) / z / b.tan_half;
  return Eigen::Vector2d(0.5 * (nx + 1.0) * width, 0.5 * (1.0 - ny) * height);
}

void parse_render_size(const std::string& text, const std::string& flag, RenderOptions& opt) {
  const auto x = text.find_first_of("xX");
  int w = 0, h = 0;
  try {
    if (x == std::string::npos) throw std::invalid_argument("no x");
    std::size_t n1 = 0, n2 = 0;
    w = std::stoi(text.substr(0, x), &n1);
    h = std::stoi(text.substr(x + 1), &n2);
    if (n1 != x || n2 != text.size() - x - 1) throw std::invalid_argument("trailing");
  } catch (const std::exception&) {
    throw InputError({"", 0, flag}, "'" + text + "' is not WIDTHxHEIGHT (e.g. 1600x900)");
  }
  if (w < 1 || h < 1 || w > kMaxSide || h > kMaxSide)
    throw InputError({"", 0, flag}, "'" + text + "': each side must be 1.." + std::to_string(kMaxSide) + " pixels");
  opt.width = w;
  opt.height = h;
}

Image render_scene(const Scene& scene, const Harness& harness, const nlohmann::json& report,
                   const RenderOptions& opt, RenderStats* stats) {
  if (opt.width < 1 || opt.height < 1 || opt.width > kMaxSide || opt.height > kMaxSide)
    throw InputError({"", 0, "--render-size"}, "image size must be 1.." + std::to_string(kMaxSide) + " pixels a side");
  const Stopwatch t0;
  RenderStats st;

  // Cable tubes, one part per routed cable; the framing box is the harness's.
  std::vector<Part> tubes;
  std::vector<std::size_t> tube_cable;
  AABB harness_box;
  const HarnessTopology topo(harness);
  SegmentCurves curves(topo);
  TubeBudget budget("render", opt.max_tube_triangles);
  const std::set<std::string> unrouted = unrouted_cable_ids(report);  // no route, nothing to draw
  for (std::size_t c = 0; c < harness.cables.size(); ++c) {
    if (unrouted.count(harness.cables[c].id)) continue;
    const auto cl = curves.cable(static_cast<int>(c));
    const double r = harness.cables[c].radius();
    if (!cl || !(r > 0.0)) continue;
    SweepOptions so;
    so.chord_tolerance = kTubeChordPerRadius * r;
    Part p;
    p.name = harness.cables[c].id;
    p.mesh = budget.sweep(*cl, r, so, harness.cables[c].id).mesh;
    harness_box.extend(p.mesh.bounds());
    tubes.push_back(std::move(p));
    tube_cable.push_back(c);
  }
  st.tube_triangles = budget.used();
  AABB frame_box = harness_box;
  if (frame_box.empty()) frame_box = scene.bounds();
  if (frame_box.empty()) frame_box.extend(Vec3::Zero());
  std::unique_ptr<EmbreeIndex> parts_index, tube_index;
  if (!scene.parts.empty()) parts_index = std::make_unique<EmbreeIndex>(scene.parts);
  if (!tubes.empty()) tube_index = std::make_unique<EmbreeIndex>(tubes);
  std::vector<Vec3> cable_points;
  for (const Part& t : tubes) cable_points.insert(cable_points.end(), t.mesh.vertices.begin(), t.mesh.vertices.end());
  const RenderCamera cam = opt.camera ? *opt.camera
                                      : least_hidden_camera(frame_box, static_cast<double>(opt.width) / opt.height,
                                                            parts_index.get(), cable_points, st.visible_cable_share);

  Image img;
  img.width = opt.width;
  img.height = opt.height;
  img.rgb.resize(static_cast<std::size_t>(opt.width) * static_cast<std::size_t>(opt.height) * 3);
  const Basis b = basis_of(cam, opt.width, opt.height);
  ProgressCounter rows(opt.progress, "render", static_cast<std::size_t>(opt.height), "rows");
  tbb::parallel_for(0, opt.height, [&](int y) {
    for (int x = 0; x < opt.width; ++x) {
      const double nx = (2.0 * (x + 0.5) / opt.width - 1.0) * b.tan_half * b.aspect;
      const double ny = (1.0 - 2.0 * (y + 0.5) / opt.height) * b.tan_half;
      const Vec3 dir = (b.f + nx * b.r + ny * b.u).normalized();
      RayHit hp, ht;
      if (parts_index) hp = parts_index->ray(cam.eye, dir);
      if (tube_index) ht = tube_index->ray(cam.eye, dir);
      const Vec3 light = (-dir + kLightLift * b.u).normalized();
      auto lit = [&](const RayHit& h, const std::array<std::uint8_t, 3>& base) {
        Vec3 n = h.normal;
        if (n.dot(dir) > 0.0) n = -n;
        return shade(base, kAmbient + kDiffuse * std::max(0.0, n.dot(light)));
      };
      std::array<std::uint8_t, 3> colour = kBackground;
      if (ht.found() && (!hp.found() || ht.t <= hp.t)) {
        colour = lit(ht, cable_colour(tube_cable[static_cast<std::size_t>(ht.part)]));
      } else if (hp.found()) {
        colour = lit(hp, scene.parts[static_cast<std::size_t>(hp.part)].role == PartRole::KeepOut ? kKeepOut : kStructure);
        // Structure is see-through where it hides a cable: the harness is what the picture shows.
        if (ht.found()) {
          const auto behind = lit(ht, cable_colour(tube_cable[static_cast<std::size_t>(ht.part)]));
          for (std::size_t k = 0; k < 3; ++k)
            colour[k] = static_cast<std::uint8_t>(std::lround((1.0 - kSeeThrough) * colour[k] + kSeeThrough * behind[k]));
        }
      }
      put(img, x, y, colour);
    }
    rows.add();
  });
  rows.finish();
  st.rays = static_cast<std::size_t>(opt.width) * static_cast<std::size_t>(opt.height);

  // Markers over everything: violations first, clashes on top.
  const double mr = opt.marker_radius_px > 0.0 ? opt.marker_radius_px
                                               : std::max(4.0, std::min(opt.width, opt.height) / 120.0);
  auto draw = [&](const char* key, bool clash, double radius_px, const std::array<std::uint8_t, 3>* fixed) {
    if (!report.contains(key) || !report[key].is_array()) return;
    for (const auto& e : report[key]) {
      const auto p = point_of(e);
      if (!p) continue;
      const auto px = project_to_pixel(cam, opt.width, opt.height, *p);
      if (!px || px->x() < -radius_px || px->y() < -radius_px || px->x() > opt.width + radius_px ||
          px->y() > opt.height + radius_px)
        continue;
      const std::string kind = e.value("kind", std::string());
      disc(img, *px, radius_px, fixed ? *fixed : clash ? kClash : (kind == "bend-radius" ? kBend : kClearance));
      ++st.markers;
    }
  };
  draw("clamps", false, 0.6 * mr, &kClamp);
  draw("violations", false, mr, nullptr);
  draw("clashes", true, mr, nullptr);
  st.ms = t0.ms();
  if (stats) *stats = st;
  return img;
}

void write_png(const std::filesystem::path& file, const Image& image) {
  write_file_atomic(file, png_bytes(image));
}

}  // namespace loom
