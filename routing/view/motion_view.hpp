#pragma once
/// What the view draws of moving parts beyond their rest pose: each moving part at the two
/// ends of its motion (role "swept", translucent: the envelope's extremes), and at the
/// pose of each cable-motion clash of a report.json (role "clash-pose", translucent red).
/// World frame, scene units.

#include "core/scene.hpp"

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace loom {

/// One extra mesh for the view.
struct PosedPartView {
  std::string name;  ///< "<part> @ <pose> <unit>"
  std::string role;  ///< "swept" | "clash-pose"
  Mesh mesh;         ///< the part's mesh moved to that pose
};

/// The extreme poses of every moving part of `scene`, then one mesh per cable-motion clash
/// of `report` (clashes[] entries of kind "cable-motion" naming a moving part of the scene
/// and a finite pose; others are skipped), in report order.
std::vector<PosedPartView> motion_view_meshes(const Scene& scene, const nlohmann::json& report);

}  // namespace loom
