#pragma once
// Scenes of the supports tests: closed boxes as parts, one straight cable along x.
#include "core/harness.hpp"
#include "core/part.hpp"

#include <string>
#include <vector>

namespace loom::test {

/// A closed box [lo, hi], outward-facing triangles, scene units.
inline Part box_part(const std::string& name, const Vec3& lo, const Vec3& hi, PartRole role = PartRole::Structure) {
  Part p;
  p.name = name;
  p.role = role;
  p.closed = true;
  for (int i = 0; i < 8; ++i)
    p.mesh.vertices.emplace_back(i & 1 ? hi.x() : lo.x(), i & 2 ? hi.y() : lo.y(), i & 4 ? hi.z() : lo.z());
  p.mesh.triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                      {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  return p;
}

/// One polyline cable C1 of `diameter` from port A (0, 0, height) to port B (length, 0,
/// height), segment A/B, with a clamp "K<x>" on it at each x of `clamp_x`.
inline Harness straight_cable(double length, double height, double diameter, const std::vector<double>& clamp_x) {
  Harness h;
  h.name = "plate";
  h.source_file = "plate.xml";
  h.ports.push_back({"A", {0, 0, height}, {1, 0, 0}, 1});
  h.ports.push_back({"B", {length, 0, height}, {-1, 0, 0}, 2});
  Segment s;
  s.from = "A";
  s.to = "B";
  s.interp = Interp::Polyline;
  h.segments.push_back(s);
  Cable c;
  c.id = "C1";
  c.ports[0] = "A";
  c.ports[1] = "B";
  c.physical.diameter = diameter;
  h.cables.push_back(c);
  for (double x : clamp_x) {
    Clamp k;
    k.id = "K" + std::to_string(static_cast<int>(x));
    k.position = {x, 0, height};
    k.segment = 0;
    h.clamps.push_back(k);
  }
  return h;
}

}  // namespace loom::test
