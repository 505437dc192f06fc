// gltf_loader.h — glTF 2.0 (.gltf and .glb) to Scene, through tinygltf.
#pragma once
#include <string>

#include "scene/scene.h"

namespace obscura::scene {

// Loads a glTF 2.0 file. Throws obscura::InputError("<file>: <element>: <problem>") on any bad
// input: missing file or buffer, accessor or index out of range, NaN/inf positions, unsupported
// primitive mode, missing or undecodable texture. Degenerate triangles are dropped and counted.
Scene loadGltf(const std::string& path);

} // namespace obscura::scene
