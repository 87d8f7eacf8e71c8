#include "core/io/mesh_read.hpp"

#include "core/error.hpp"
#include "core/io/dae_geometry.hpp"
#include "core/io/glb_container.hpp"
#include "core/io/gltf_geometry.hpp"
#include "core/io/input_file.hpp"
#include "core/io/mesh_file_checks.hpp"
#include "core/io/step_file_checks.hpp"

#include <nlohmann/json.hpp>

#include <assimp/DefaultIOSystem.h>
#include <assimp/Importer.hpp>
#include <assimp/MemoryIOWrapper.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <BRepBndLib.hxx>
#include <BRepMesh_IncrementalMesh.hxx>
#include <BRepTools.hxx>
#include <Bnd_Box.hxx>
#include <BRep_Tool.hxx>
#include <IGESCAFControl_Reader.hxx>
#include <IFSelect_ReturnStatus.hxx>
#include <Interface_Static.hxx>
#include <Message.hxx>
#include <Message_Messenger.hxx>
#include <Message_PrinterOStream.hxx>
#include <Poly_Triangulation.hxx>
#include <STEPCAFControl_Reader.hxx>
#include <Standard_Failure.hxx>
#include <TDF_ChildIterator.hxx>
#include <TDF_Label.hxx>
#include <TDF_LabelSequence.hxx>
#include <TDataStd_Name.hxx>
#include <TDocStd_Document.hxx>
#include <TopExp_Explorer.hxx>
#include <TopLoc_Location.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Compound.hxx>
#include <TopoDS_Face.hxx>
#include <BRep_Builder.hxx>
#include <XCAFApp_Application.hxx>
#include <XCAFDoc_DocumentTool.hxx>
#include <XCAFDoc_ShapeTool.hxx>

#include <algorithm>
#include <cctype>
#include <cstring>
#include <map>
#include <set>
#include <system_error>

namespace loom {

namespace {

/// Assimp's file system restricted to regular files. Assimp opens the files a mesh refers to
/// itself (an OBJ's mtllib, a glTF buffer or image uri, a DAE image); a FIFO there blocks the
/// read forever and a device never ends, so to Assimp such a path does not exist.
/// It can also serve one file from memory in place of its bytes on disk (serve()).
class RegularFilesOnly : public Assimp::DefaultIOSystem {
 public:
  bool Exists(const char* file) const override { return regular(file) && DefaultIOSystem::Exists(file); }
  Assimp::IOStream* Open(const char* file, const char* mode = "rb") override {
    if (file && !served_path_.empty() && served_path_ == file)
      return new Assimp::MemoryIOStream(reinterpret_cast<const std::uint8_t*>(served_.data()), served_.size());
    return regular(file) ? DefaultIOSystem::Open(file, mode) : nullptr;
  }
  /// Opening `path` (as given to ReadFile) reads `bytes` instead of the file.
  void serve(const std::string& path, std::string bytes) {
    served_path_ = path;
    served_ = std::move(bytes);
  }

 private:
  static bool regular(const char* file) {
    std::error_code ec;
    return file && std::filesystem::is_regular_file(file, ec);
  }
  std::string served_path_, served_;
};


void finish_mesh(Mesh& m, const std::filesystem::path& path, const std::string& what) {
  const long bad = first_non_finite_vertex(m);
  if (bad >= 0)
    throw InputError({path.string(), 0, what}, "vertex " + std::to_string(bad) + " has a NaN or infinite coordinate");
  weld_identical_vertices(m);
}
}  // namespace

std::string obj_text_for_assimp(std::string text) {
  bool continued = false;  // the previous line ended in a backslash: this one continues it
  for (std::size_t at = 0; at < text.size();) {
    std::size_t end = text.find('\n', at);
    if (end == std::string::npos) end = text.size();
    std::size_t first = at;
    while (first < end && (text[first] == ' ' || text[first] == '\t')) ++first;
    auto statement = [&](const char* word) {
      const std::size_t n = std::strlen(word);
      return text.compare(first, n, word) == 0 &&
             (first + n == end || text[first + n] == ' ' || text[first + n] == '\t' || text[first + n] == '\r');
    };
    if (!continued && (statement("o") || statement("usemtl"))) text[first] = '#';
    std::size_t last = end;
    while (last > at && (text[last - 1] == '\r' || text[last - 1] == ' ' || text[last - 1] == '\t')) --last;
    continued = last > at && text[last - 1] == '\\';
    at = end + 1;
  }
  return text;
}

bool is_cad_file(const std::filesystem::path& p) {
  const auto e = lower_extension(p);
  return e == ".step" || e == ".stp" || e == ".iges" || e == ".igs";
}

bool is_mesh_file(const std::filesystem::path& p) {
  const auto e = lower_extension(p);
  return e == ".stl" || e == ".obj" || e == ".ply" || e == ".off" || e == ".gltf" || e == ".glb" || e == ".dae";
}

Mesh read_mesh_file(const std::filesystem::path& path) {
  require_input_file(path, "file");
  if (!is_mesh_file(path))
    throw InputError({path.string(), 0, ""}, "unknown mesh extension '" + path.extension().string() +
                                                 "' (meshes: .stl .obj .ply .off .gltf .glb .dae; CAD: .step .stp .iges .igs)");
  check_mesh_file_structure(path);  // declared counts and nesting Assimp would trust
  Assimp::Importer importer;
  auto* io = new RegularFilesOnly;
  importer.SetIOHandler(io);  // the importer owns and deletes it
  const std::string ext = lower_extension(path);
  if (ext == ".obj") io->serve(path.string(), obj_text_for_assimp(file_bytes(path)));
  if (ext == ".dae") io->serve(path.string(), dae_geometry_for_assimp(file_bytes(path)));
  if (ext == ".gltf" || ext == ".glb") {
    // Parsed and checked by check_mesh_file_structure; Assimp reads the geometry alone.
    const nlohmann::json doc = nlohmann::json::parse(gltf_json(path, ext == ".glb"));
    if (auto geometry = gltf_geometry_for_assimp(doc, path, ext == ".glb")) io->serve(path.string(), std::move(*geometry));
  }
  // Points and lines are dropped; node transforms are baked in so one mesh results.
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  // ValidateDataStructure runs before the other steps: a face index beyond the vertices (which
  // Assimp's PLY reader passes on) is refused there instead of read out of bounds by them.
  const aiScene* sc = importer.ReadFile(path.string(), aiProcess_ValidateDataStructure | aiProcess_Triangulate |
                                                           aiProcess_JoinIdenticalVertices |
                                                           aiProcess_PreTransformVertices | aiProcess_SortByPType);
  if (!sc) throw InputError({path.string(), 0, ""}, std::string("cannot read mesh: ") + importer.GetErrorString());
  Mesh m;
  for (unsigned i = 0; i < sc->mNumMeshes; ++i) {
    const aiMesh* am = sc->mMeshes[i];
    if (!(am->mPrimitiveTypes & aiPrimitiveType_TRIANGLE)) continue;
    const auto base = static_cast<std::uint32_t>(m.vertices.size());
    for (unsigned v = 0; v < am->mNumVertices; ++v)
      m.vertices.emplace_back(am->mVertices[v].x, am->mVertices[v].y, am->mVertices[v].z);
    for (unsigned f = 0; f < am->mNumFaces; ++f) {
      const aiFace& face = am->mFaces[f];
      if (face.mNumIndices != 3) continue;
      for (unsigned k = 0; k < 3; ++k)
        if (face.mIndices[k] >= am->mNumVertices)
          throw InputError({path.string(), 0, "face " + std::to_string(f)},
                           "vertex index " + std::to_string(face.mIndices[k]) + " is beyond the mesh's " +
                               std::to_string(am->mNumVertices) + " vertices");
      m.triangles.push_back({base + face.mIndices[0], base + face.mIndices[1], base + face.mIndices[2]});
    }
  }
  finish_mesh(m, path, "");
  if (m.empty()) throw InputError({path.string(), 0, ""}, "the mesh has no triangles");
  return m;
}

namespace {

/// Appends the triangulation of every face of `shape` (already meshed) to `out`,
/// honouring face orientation and locations, scaled by `scale`. Returns the face count.
int append_triangulation(const TopoDS_Shape& shape, double scale, Mesh& out) {
  int faces = 0;
  for (TopExp_Explorer ex(shape, TopAbs_FACE); ex.More(); ex.Next()) {
    const TopoDS_Face& face = TopoDS::Face(ex.Current());
    ++faces;
    TopLoc_Location loc;
    Handle(Poly_Triangulation) tri = BRep_Tool::Triangulation(face, loc);
    if (tri.IsNull()) continue;
    const gp_Trsf tr = loc.Transformation();
    const auto base = static_cast<std::uint32_t>(out.vertices.size());
    for (Standard_Integer i = 1; i <= tri->NbNodes(); ++i) {
      gp_Pnt p = tri->Node(i).Transformed(tr);
      out.vertices.emplace_back(p.X() * scale, p.Y() * scale, p.Z() * scale);
    }
    const bool reversed = face.Orientation() == TopAbs_REVERSED;
    for (Standard_Integer i = 1; i <= tri->NbTriangles(); ++i) {
      Standard_Integer a, b, c;
      tri->Triangle(i).Get(a, b, c);
      if (reversed) std::swap(b, c);
      out.triangles.push_back({base + static_cast<std::uint32_t>(a - 1), base + static_cast<std::uint32_t>(b - 1),
                               base + static_cast<std::uint32_t>(c - 1)});
    }
  }
  return faces;
}

std::string label_name(const TDF_Label& l) {
  Handle(TDataStd_Name) n;
  if (l.FindAttribute(TDataStd_Name::GetID(), n)) {
    TCollection_AsciiString s(n->Get());
    return s.ToCString();
  }
  return "";
}

struct Leaf {
  std::string name;
  TopoDS_Shape shape;  // located in the assembly frame
};

void collect_leaves(const Handle(XCAFDoc_ShapeTool)& tool, const TDF_Label& label, const TopLoc_Location& loc,
                    std::vector<Leaf>& out) {
  TDF_Label ref = label;
  TopLoc_Location here = loc;
  std::string instance_name = label_name(label);
  if (XCAFDoc_ShapeTool::IsReference(label)) {
    XCAFDoc_ShapeTool::GetReferredShape(label, ref);
    here = loc * XCAFDoc_ShapeTool::GetLocation(label);
  }
  if (XCAFDoc_ShapeTool::IsAssembly(ref)) {
    TDF_LabelSequence comps;
    XCAFDoc_ShapeTool::GetComponents(ref, comps);
    for (Standard_Integer i = 1; i <= comps.Length(); ++i) collect_leaves(tool, comps.Value(i), here, out);
    return;
  }
  TopoDS_Shape s = XCAFDoc_ShapeTool::GetShape(ref);
  if (s.IsNull()) return;
  std::string name = label_name(ref);
  if (name.empty()) name = instance_name;
  out.push_back({name, s.Moved(here)});
}

/// Smallest linear deflection accepted, as a fraction of the file's bounding-box diagonal.
/// Below it OpenCASCADE's mesher either throws (Standard_NumericError at ~1e-12 of the size)
/// or produces more triangles than memory holds; a cable needs nothing that fine.
constexpr double kMinRelativeDeflection = 1e-6;
constexpr const char* kMinRelativeDeflectionText = "1e-6";

std::shared_ptr<CadShapes> transfer_cad_file(const std::filesystem::path& path);
std::vector<NamedMesh> mesh_cad_shapes(CadShapes& shapes, const std::filesystem::path& path,
                                       const TessellationParams& tp, bool split, const std::vector<int>* only_leaves);
}  // namespace

struct CadShapes {
  std::vector<Leaf> leaves;
  double diagonal_mm = 0.0;  ///< of the leaves' bounding box (0: void)
  bool meshed = false;       ///< some leaf carries a triangulation from an earlier meshing
};

CadShapeStore::CadShapeStore() = default;
CadShapeStore::~CadShapeStore() = default;

std::shared_ptr<CadShapes> CadShapeStore::find(const std::filesystem::path& path) const {
  const auto it = files_.find(path.string());
  return it == files_.end() ? nullptr : it->second;
}

void CadShapeStore::add(const std::filesystem::path& path, std::shared_ptr<CadShapes> shapes) {
  files_[path.string()] = std::move(shapes);
}

std::vector<NamedMesh> read_cad_file(const std::filesystem::path& path, const TessellationParams& tp, bool split,
                                     const std::vector<int>* only_leaves, CadShapeStore* store) {
  // OpenCASCADE reports failures of its readers and mesher by exceptions of its own: they
  // are the file's (or the deflection's) fault, so they become input errors naming both.
  try {
    require_input_file(path, "file");
    if (!is_cad_file(path))
      throw InputError({path.string(), 0, ""}, "not a STEP/IGES file: '" + path.extension().string() + "'");
    if (!(tp.linear_deflection > 0.0))
      throw InputError({path.string(), 0, ""}, "tessellation deflection must be positive");
    std::shared_ptr<CadShapes> shapes = store ? store->find(path) : nullptr;
    if (!shapes) {
      shapes = transfer_cad_file(path);
      if (store) store->add(path, shapes);
    }
    return mesh_cad_shapes(*shapes, path, tp, split, only_leaves);
  } catch (const Standard_Failure& e) {
    throw InputError({path.string(), 0, ""}, std::string("OpenCASCADE failed (") + e.DynamicType()->Name() +
                                                 "): " + (e.GetMessageString() ? e.GetMessageString() : "") +
                                                 " (tessellation deflection " + full_precision(tp.linear_deflection) +
                                                 " scene units)");
  }
}

namespace {
/// Parses and transfers a STEP/IGES file: its leaf products in the assembly frame (mm).
std::shared_ptr<CadShapes> transfer_cad_file(const std::filesystem::path& path) {
  Handle(XCAFApp_Application) app = XCAFApp_Application::GetApplication();
  Handle(TDocStd_Document) doc;
  app->NewDocument("MDTV-XCAF", doc);
  const std::string ext = lower_extension(path);
  // OpenCASCADE converts lengths to millimetres on transfer; we then scale to scene units.
  Interface_Static::SetCVal("xstep.cascade.unit", "MM");
  bool ok = false;
  if (ext == ".step" || ext == ".stp") {
    check_step_references(path);  // OpenCASCADE's transfer follows a dangling one
    STEPCAFControl_Reader reader;
    reader.SetNameMode(true);
    if (reader.ReadFile(path.string().c_str()) != IFSelect_RetDone)
      throw InputError({path.string(), 0, ""}, "cannot parse STEP file");
    ok = reader.Transfer(doc);
  } else {
    IGESCAFControl_Reader reader;
    reader.SetNameMode(true);
    if (reader.ReadFile(path.string().c_str()) != IFSelect_RetDone)
      throw InputError({path.string(), 0, ""}, "cannot parse IGES file");
    ok = reader.Transfer(doc);
  }
  if (!ok) throw InputError({path.string(), 0, ""}, "OpenCASCADE could not transfer the file's shapes");
  Handle(XCAFDoc_ShapeTool) tool = XCAFDoc_DocumentTool::ShapeTool(doc->Main());
  TDF_LabelSequence roots;
  tool->GetFreeShapes(roots);
  std::vector<Leaf> leaves;
  for (Standard_Integer i = 1; i <= roots.Length(); ++i) collect_leaves(tool, roots.Value(i), TopLoc_Location(), leaves);
  app->Close(doc);
  if (leaves.empty()) throw InputError({path.string(), 0, ""}, "the file contains no shapes");
  auto shapes = std::make_shared<CadShapes>();
  Bnd_Box bb;
  for (const auto& l : leaves) BRepBndLib::Add(l.shape, bb);
  if (!bb.IsVoid()) shapes->diagonal_mm = std::sqrt(bb.SquareExtent());
  shapes->leaves = std::move(leaves);
  return shapes;
}

/// Meshes transferred shapes as read_cad_file describes. Shapes meshed before lose that
/// triangulation first, so that the meshes are those of a fresh reading whatever came
/// before (OpenCASCADE's mesher keeps a finer triangulation it finds).
std::vector<NamedMesh> mesh_cad_shapes(CadShapes& shapes, const std::filesystem::path& path,
                                       const TessellationParams& tp, bool split, const std::vector<int>* only_leaves) {
  const std::vector<Leaf>& leaves = shapes.leaves;
  if (shapes.meshed)
    for (const auto& l : leaves) BRepTools::Clean(l.shape);
  shapes.meshed = true;
  const double scale = 1.0 / tp.unit_in_mm;
  // Deflection is given in scene units; OpenCASCADE meshes in the file's (mm) frame.
  const double lin_mm = tp.linear_deflection * tp.unit_in_mm;
  if (lin_mm < kMinRelativeDeflection * shapes.diagonal_mm)
    throw InputError({path.string(), 0, ""},
                     "tessellation deflection " + full_precision(tp.linear_deflection) + " scene units is below " +
                         kMinRelativeDeflectionText + " of the file's size (" +
                         full_precision(shapes.diagonal_mm * scale) +
                         " scene units): raise tessellation.linear_deflection, or the smallest cable diameter "
                         "its default follows");
  const double ang = tp.angular_deflection_deg * M_PI / 180.0;
  std::vector<NamedMesh> out;
  if (!split) {
    BRep_Builder bb;
    TopoDS_Compound comp;
    bb.MakeCompound(comp);
    for (const auto& l : leaves) bb.Add(comp, l.shape);
    BRepMesh_IncrementalMesh mesher(comp, lin_mm, false, ang, true);
    NamedMesh nm;
    nm.name = leaves.size() == 1 ? leaves[0].name : path.stem().string();
    nm.brep_faces = append_triangulation(comp, scale, nm.mesh);
    finish_mesh(nm.mesh, path, nm.name);
    if (nm.mesh.empty()) throw InputError({path.string(), 0, ""}, "tessellation produced no triangles");
    out.push_back(std::move(nm));
    return out;
  }
  // Names given so far: a repeated product gets the first free "#k" suffix, free also of
  // products whose own names end so ("bolt", "bolt", "bolt#2" must give three names).
  std::set<std::string> used;
  std::map<std::string, int> next_suffix;  // per product name: the first k not yet tried
  for (std::size_t i = 0; i < leaves.size(); ++i) {
    const Leaf& l = leaves[i];
    NamedMesh nm;
    const std::string base = l.name.empty() ? "solid" : l.name;
    nm.name = base;
    nm.leaf = static_cast<int>(i);
    int& k = next_suffix.try_emplace(base, 2).first->second;
    while (!used.insert(nm.name).second) nm.name = base + "#" + std::to_string(k++);
    if (only_leaves && !std::binary_search(only_leaves->begin(), only_leaves->end(), nm.leaf)) continue;
    BRepMesh_IncrementalMesh mesher(l.shape, lin_mm, false, ang, true);
    nm.brep_faces = append_triangulation(l.shape, scale, nm.mesh);
    finish_mesh(nm.mesh, path, nm.name);
    if (nm.mesh.empty()) continue;  // e.g. a wire-frame or empty product: nothing to collide with
    out.push_back(std::move(nm));
  }
  if (out.empty() && !only_leaves) throw InputError({path.string(), 0, ""}, "tessellation produced no triangles");
  return out;
}

}  // namespace

void silence_opencascade_console() {
  Message::DefaultMessenger()->RemovePrinters(STANDARD_TYPE(Message_PrinterOStream));
}

}  // namespace loom
