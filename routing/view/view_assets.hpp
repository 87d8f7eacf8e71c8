#pragma once
/// The JavaScript that view.html inlines: three.js r111 and its OrbitControls from Debian's
/// libjs-three, compiled into the binary by cmake/LoomViewAssets.cmake (generated source).

#include <string>

namespace loom::view_assets {

/// three.min.js (r111) exactly as installed by libjs-three; defines the global THREE.
const std::string& three_js();
/// examples/js/controls/OrbitControls.js (r111); adds THREE.OrbitControls.
const std::string& orbit_controls_js();

}  // namespace loom::view_assets
