// STEP export of a tube: lateral NURBS face from the sweep sections + planar caps, sewn
// into a solid, checked, written.
#include "routing/curve/sweep_step.hpp"

#include <BRepBuilderAPI_MakeEdge.hxx>
#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepBuilderAPI_MakeSolid.hxx>
#include <BRepBuilderAPI_MakeWire.hxx>
#include <BRepBuilderAPI_Sewing.hxx>
#include <BRepCheck_Analyzer.hxx>
#include <BRepGProp.hxx>
#include <GProp_GProps.hxx>
#include <Geom_BSplineSurface.hxx>
#include <Geom_Circle.hxx>
#include <IFSelect_ReturnStatus.hxx>
#include <Interface_Static.hxx>
#include <STEPControl_Writer.hxx>
#include <Standard_Failure.hxx>
#include <TColStd_Array1OfInteger.hxx>
#include <TColStd_Array1OfReal.hxx>
#include <TColStd_Array2OfReal.hxx>
#include <TColgp_Array2OfPnt.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Shell.hxx>
#include <TopoDS_Wire.hxx>
#include <TopoDS_Solid.hxx>

#include <array>
#include <cmath>
#include <system_error>

namespace loom {

namespace {

/// Sewing tolerance relative to the tube radius (the cap circles and the lateral face's
/// boundary iso-curves are the same circles up to rounding).
constexpr double kSewingRelTol = 1e-7;

/// Relative accuracy of the reported volume and area (adaptive integration).
constexpr double kPropertiesRelTol = 1e-7;

gp_Pnt pnt(const Vec3& v) { return gp_Pnt(v.x(), v.y(), v.z()); }
gp_Dir dir(const Vec3& v) { return gp_Dir(v.x(), v.y(), v.z()); }

/// Knots with multiplicities of a clamped knot vector.
void compress(const std::vector<double>& U, std::vector<double>& k, std::vector<int>& m) {
  for (double u : U) {
    if (!k.empty() && u == k.back())
      ++m.back();
    else {
      k.push_back(u);
      m.push_back(1);
    }
  }
}

TopoDS_Face cap(const SweepSection& g, bool at_start) {
  // Planar disc bounded by the section circle; its normal points out of the tube.
  const Vec3 n = at_start ? Vec3(-g.tangent) : g.tangent;
  Handle(Geom_Circle) circle = new Geom_Circle(gp_Ax2(pnt(g.centre), dir(n), dir(g.normal)), g.radius);
  const TopoDS_Edge e = BRepBuilderAPI_MakeEdge(circle);
  const TopoDS_Wire w = BRepBuilderAPI_MakeWire(e);
  return BRepBuilderAPI_MakeFace(w, Standard_True);
}

}  // namespace

StepExportResult write_tube_step(const Centerline& c, double radius, const std::filesystem::path& path,
                                 const SweepOptions& opt, const std::string& length_unit) {
  const std::vector<SweepSection> sec = tube_sections(c, radius, opt);
  StepExportResult res;
  res.sections = static_cast<int>(sec.size());

  // Rational quadratic circle: 9 poles on the square around the unit circle.
  const double w2 = std::sqrt(0.5);
  const std::array<std::array<double, 3>, 9> unit = {{{1, 0, 1},
                                                       {1, 1, w2},
                                                       {0, 1, 1},
                                                       {-1, 1, w2},
                                                       {-1, 0, 1},
                                                       {-1, -1, w2},
                                                       {0, -1, 1},
                                                       {1, -1, w2},
                                                       {1, 0, 1}}};
  // Each of the 9 pole columns is interpolated across the sections at the sections' arc
  // lengths: the same parameters give all columns the same knots.
  std::vector<double> params;
  params.reserve(sec.size());
  for (const SweepSection& g : sec) params.push_back(g.s);
  std::vector<Centerline> columns;
  columns.reserve(9);
  for (const auto& q : unit) {
    std::vector<Vec3> pts;
    pts.reserve(sec.size());
    for (const SweepSection& g : sec)
      pts.push_back(g.centre + g.radius * (q[0] * g.normal + q[1] * g.tangent.cross(g.normal)));
    columns.push_back(Centerline::interpolate(pts, params, InterpolationOptions{}));
  }
  const int nv = static_cast<int>(columns[0].control_points().size());
  TColgp_Array2OfPnt poles(1, 9, 1, nv);
  TColStd_Array2OfReal weights(1, 9, 1, nv);
  for (int j = 0; j < 9; ++j)
    for (int k = 0; k < nv; ++k) {
      poles.SetValue(j + 1, k + 1, pnt(columns[j].control_points()[k]));
      weights.SetValue(j + 1, k + 1, unit[j][2]);
    }
  TColStd_Array1OfReal uk(1, 5);
  TColStd_Array1OfInteger um(1, 5);
  const double uknots[5] = {0, 0.25, 0.5, 0.75, 1};
  const int umults[5] = {3, 2, 2, 2, 3};
  for (int i = 0; i < 5; ++i) {
    uk.SetValue(i + 1, uknots[i]);
    um.SetValue(i + 1, umults[i]);
  }
  std::vector<double> vk;
  std::vector<int> vm;
  compress(columns[0].knots(), vk, vm);
  TColStd_Array1OfReal vkn(1, static_cast<int>(vk.size()));
  TColStd_Array1OfInteger vmu(1, static_cast<int>(vk.size()));
  for (std::size_t i = 0; i < vk.size(); ++i) {
    vkn.SetValue(static_cast<int>(i) + 1, vk[i]);
    vmu.SetValue(static_cast<int>(i) + 1, vm[i]);
  }

  try {
    Handle(Geom_BSplineSurface) surf = new Geom_BSplineSurface(poles, weights, uk, vkn, um, vmu, 2, 3);
    const TopoDS_Face lateral = BRepBuilderAPI_MakeFace(surf, kSewingRelTol * radius);
    BRepBuilderAPI_Sewing sew(kSewingRelTol * radius * 10.0);
    sew.Add(lateral);
    sew.Add(cap(sec.front(), true));
    sew.Add(cap(sec.back(), false));
    sew.Perform();
    TopExp_Explorer ex(sew.SewedShape(), TopAbs_SHELL);
    if (!ex.More()) {
      res.status = StepExportStatus::InvalidShape;
      res.message = "sewing the lateral face and the caps gave no shell";
      return res;
    }
    const TopoDS_Shell shell = TopoDS::Shell(ex.Current());
    BRepBuilderAPI_MakeSolid ms(shell);
    TopoDS_Solid solid = ms.Solid();
    GProp_GProps vp;
    BRepGProp::VolumeProperties(solid, vp, kPropertiesRelTol);
    if (vp.Mass() < 0.0) {
      solid.Reverse();
      BRepGProp::VolumeProperties(solid, vp, kPropertiesRelTol);
    }
    GProp_GProps sp;
    BRepGProp::SurfaceProperties(solid, sp, kPropertiesRelTol);
    res.volume = vp.Mass();
    res.area = sp.Mass();
    BRepCheck_Analyzer check(solid);
    if (!check.IsValid() || !shell.Closed()) {
      res.status = StepExportStatus::InvalidShape;
      res.message = "OpenCASCADE reports the tube solid as invalid or open";
      return res;
    }
    STEPControl_Writer writer;
    Interface_Static::SetCVal("write.step.unit", length_unit.c_str());
    if (writer.Transfer(solid, STEPControl_AsIs) != IFSelect_RetDone) {
      res.status = StepExportStatus::WriteFailed;
      res.message = "the STEP writer could not transfer the solid";
      return res;
    }
    std::error_code ec;
    if (path.has_parent_path()) std::filesystem::create_directories(path.parent_path(), ec);
    const std::filesystem::path tmp = path.string() + ".tmp";
    if (writer.Write(tmp.string().c_str()) != IFSelect_RetDone) {
      std::filesystem::remove(tmp, ec);
      res.status = StepExportStatus::WriteFailed;
      res.message = "cannot write " + tmp.string();
      return res;
    }
    std::filesystem::rename(tmp, path, ec);
    if (ec) {
      std::filesystem::remove(tmp, ec);
      res.status = StepExportStatus::WriteFailed;
      res.message = "cannot rename onto " + path.string() + ": " + ec.message();
      return res;
    }
  } catch (const Standard_Failure& f) {
    res.status = StepExportStatus::InvalidShape;
    res.message = std::string("OpenCASCADE: ") + f.GetMessageString();
    return res;
  }
  res.status = StepExportStatus::Written;
  return res;
}

}  // namespace loom
