#pragma once
/// Test oracle helper: a loom Centerline as OpenCASCADE's own B-spline, so that
/// OpenCASCADE's evaluation, curvature and arc length can judge loom's.

#include "core/centerline.hpp"

#include <Geom_BSplineCurve.hxx>
#include <TColStd_Array1OfInteger.hxx>
#include <TColStd_Array1OfReal.hxx>
#include <TColgp_Array1OfPnt.hxx>

#include <cstddef>
#include <vector>

namespace loom::test_oracle {

/// The same curve as an OpenCASCADE Geom_BSplineCurve (knots with multiplicities).
inline Handle(Geom_BSplineCurve) to_occt(const Centerline& c) {
  std::vector<double> k;
  std::vector<int> m;
  for (double u : c.knots()) {
    if (!k.empty() && u == k.back())
      ++m.back();
    else {
      k.push_back(u);
      m.push_back(1);
    }
  }
  TColgp_Array1OfPnt poles(1, static_cast<int>(c.control_points().size()));
  for (int i = 0; i < poles.Length(); ++i) {
    const Vec3& p = c.control_points()[static_cast<std::size_t>(i)];
    poles.SetValue(i + 1, gp_Pnt(p.x(), p.y(), p.z()));
  }
  TColStd_Array1OfReal knots(1, static_cast<int>(k.size()));
  TColStd_Array1OfInteger mults(1, static_cast<int>(k.size()));
  for (std::size_t i = 0; i < k.size(); ++i) {
    knots.SetValue(static_cast<int>(i) + 1, k[i]);
    mults.SetValue(static_cast<int>(i) + 1, m[i]);
  }
  return new Geom_BSplineCurve(poles, knots, mults, c.degree());
}

}  // namespace loom::test_oracle
