// Reading scenes from YAML (format documented in docs/scene-format.md).
#pragma once

#include <string>
#include <vector>

#include "models/scene.hpp"

namespace rdyn::models {

// One `--set key=value` override: a dotted path into the YAML tree. Map keys by name,
// sequence items by index or by the value of their `name` field
// (e.g. `loads.brake.coefficient=0.3`, `bicycle_leg.subject.height_m=1.80`).
struct Override {
  std::string path;
  std::string value;
};

// Parses "key=value"; throws SceneError (field "--set") when malformed.
Override parse_override(const std::string& text);

// Resolves a shipped scene name or a path. A name is looked up in $RDYN_SCENES_DIR, then in
// an installed rdyn's share/rdyn/scenes (found from the executable's own location), then in
// the source folder models/scenes. Throws SceneError when neither exists.
std::string resolve_scene_path(const std::string& name_or_path);

// Reads, overrides, expands generators (bicycle_leg) and checks a scene.
// Every problem throws SceneError naming the file (and line and field where known).
Scene load_scene(const std::string& name_or_path, const std::vector<Override>& overrides = {});

// Same, from YAML text already in memory; `file` is used in messages.
Scene parse_scene(const std::string& yaml_text, const std::string& file,
                  const std::vector<Override>& overrides = {});

// The text of a scene file (resolved like load_scene). Throws SceneError; "not a regular file"
// for a FIFO, folder, device or socket (checked before opening: a FIFO without a writer would
// block, a device never ends).
std::string read_scene_text(const std::string& name_or_path);

// What `path` is when it is not a regular file (links followed): "a FIFO", "a folder", "a
// character device", "a block device", "a socket"; empty for a regular file or a path that
// cannot be looked at (opening it reports that). Input files are refused on a non-empty answer.
std::string non_regular_file_kind(const std::string& path);

// An input text as rdyn writes it: an editor's UTF-8 byte-order mark dropped, and lines ended by
// CR alone (classic Mac) ended by \n. Neither changes a value; tables and drive profiles read
// through it (they were refused as a checksum mismatch or a garbled header).
std::string normalise_text_encoding(std::string text);

// Whether a dotted key path (as in overrides) exists in the scene's YAML.
bool scene_yaml_has(const std::string& yaml_text, const std::string& path);

// Removes the key paths that exist, applies the overrides, and returns the YAML re-emitted
// (comments are not kept). Throws SceneError.
std::string rewrite_scene_yaml(const std::string& yaml_text, const std::string& file,
                               const std::vector<Override>& overrides, const std::vector<std::string>& remove);

}  // namespace rdyn::models
