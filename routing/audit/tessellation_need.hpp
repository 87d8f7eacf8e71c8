#pragma once
/// Tessellation by need (DESIGN §7): a CAD part is meshed at the scene's coarse deflection
/// first and again at the fine one only if a cable comes within reach of it. Why it keeps
/// the audit's certificate: a finding against a part needs a centreline point c closer to
/// its surface than r + required clearance + tolerance; the coarse mesh lies within its
/// deflection d of the surface, and a sample of the centreline within h/2 of c, so some
/// sample comes within r + required + tolerance + d + h/2 of the coarse mesh, or lies
/// inside it. A part no sample comes that near holds no finding, coarse or fine.

#include "core/part.hpp"
#include "core/scene.hpp"
#include "routing/audit/clash_check.hpp"

#include <cstddef>
#include <string>
#include <vector>

namespace loom {

class CadShapeStore;  // core/io/mesh_read.hpp

/// What tessellation by need did (report.json "tessellation").
struct TessellationByNeed {
  bool used = false;               ///< the scene asked for it ([tessellation] by_need)
  double coarse_deflection = 0.0;  ///< scene units
  double fine_deflection = 0.0;    ///< scene units
  std::vector<int> refined;        ///< parts meshed again at the fine deflection (ascending)
  std::size_t coarse_parts = 0;    ///< CAD parts left at the coarse deflection
  double ms = 0.0;                 ///< the need test and the refinement
};

/// The CAD parts of `parts` meshed coarser than `fine_deflection` that some cable sample
/// (every r along the centreline) comes within r + required clearance + `tolerance` + the
/// part's deflection + r/2 of, or lies inside (closed parts): ascending part indices.
/// `routing_clearance` is the scene's; each part adds its own. Threads: TBB, all cores.
std::vector<int> parts_within_reach(const std::vector<Part>& parts, const std::vector<CableInput>& cables,
                                    double routing_clearance, double fine_deflection, double tolerance);

/// The report's note on what tessellation by need did ("" when it was not used).
std::string tessellation_note(const TessellationByNeed& t);

/// Refines the scene's coarse CAD parts that the cables come within reach of
/// (retessellate_parts at the fine deflection) and says what it did; nothing when the
/// scene does not ask for tessellation by need.
TessellationByNeed tessellate_by_need(Scene& scene, const std::vector<CableInput>& cables, double tolerance,
                                      CadShapeStore* cad_shapes = nullptr);

}  // namespace loom
