#pragma once
/// The part of a COLLADA (.dae) document that loom hands to Assimp: its geometry alone.
///
/// loom reads a COLLADA file's meshes and node transforms, nothing else. Assimp 5.2 reads
/// everything, and its readers of what loom ignores trust their input: a skin's joint or
/// weight index beyond its arrays, a `<vertex_weights>` count of 4·10⁹, an animation
/// channel writing past its transform, an effect parameter naming itself (a hang) — each
/// crashed, aborted, hung or allocated gigabytes. Assimp therefore reads the document
/// reduced to its asset (units), geometries, nodes and visual scenes, and the pre-check
/// (core/io/mesh_node_checks) checks that reduced document.

#include <pugixml.hpp>

#include <string>

namespace loom {

/// pugixml's options for COLLADA: Assimp's reading of text (character references
/// expanded, line ends normalised), without the nodes neither reads (comments, PIs).
constexpr unsigned kDaeParseOptions = pugi::parse_default;

/// Removes from `doc` what loom does not read: every library but those of geometries,
/// nodes and visual scenes (animations, controllers, effects, materials, images, cameras,
/// lights, physics, ...), the scene's instances other than its visual scene, the
/// instances of controllers, cameras and lights in nodes, and the material bindings of
/// geometry instances.
void keep_dae_geometry(pugi::xml_document& doc);

/// `text`, a COLLADA document that parses, reduced by keep_dae_geometry, as text.
std::string dae_geometry_for_assimp(const std::string& text);

}  // namespace loom
