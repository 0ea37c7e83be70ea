// Writing a scene back as YAML: the expanded scene (generators already applied, every value
// explicit) in the format models/scene_yaml.cpp reads (docs/scene-format.md, "Writing a scene").
#pragma once

#include <string>

#include "models/scene.hpp"

namespace rdyn::models {

// The scene as YAML text that parse_scene reads back to an equal Scene, field by field and bit for
// bit: numbers in the shortest text that reads back to the same double, angles in radians
// (offset_rad, guess_rad, table_rad, q; the degrees follow as comments), points and directions as
// coordinates, every load with its name, every default written out. Strings are written plain when
// YAML reads them back as the same text, double-quoted and escaped otherwise. Not kept: the
// original file's comments and layout, generator blocks (bicycle_leg: the bodies and joints it made
// are written instead), named-point references (their coordinates are written), `dissipates` (the
// coefficient it gave is written).
//
// Bytes that are not UTF-8 (the reader takes them as they are) are written as they are. Throws
// SceneError (file: the scene's source_file, the field) for a number no scene file can hold:
// non-finite or subnormal. A scene that load_scene returned never has one.
std::string scene_to_yaml(const Scene& scene);

// scene_to_yaml, then the text read back (parse_scene, as the scene's source_file) and written
// again: returns the text when both writings and the scene hashes (models/scene_hash.hpp) agree.
// Throws SceneError when the text does not load (a scene check_scene refuses) and NumericalError
// when it loads as another scene (a field the format cannot express, such as an axis on a revolute
// joint set in code). What `rdyn expand` writes.
std::string scene_to_yaml_checked(const Scene& scene);

}  // namespace rdyn::models
