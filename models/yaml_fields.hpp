// Checked reading of a scene's YAML (models/scene_yaml.cpp and its section readers): bounded
// tree walks, `--set` overrides applied to the tree, and Fields, a mapping whose keys are checked
// against the allowed set and whose typed getters throw SceneError with file, line and field.
// Internal to models/: the public interface is models/scene_yaml.hpp.
#pragma once

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "models/scene.hpp"
#include "models/scene_yaml.hpp"

namespace rdyn::models::yaml {

inline constexpr double kPi = 3.14159265358979323846;
// Limits on the text, checked before anything reads a value: scenes are a few kilobytes; these
// bounds are orders of magnitude above that and keep any input's memory and time small.
inline constexpr size_t kMaxSceneBytes = 1 << 20;
inline constexpr size_t kMaxOverrideKeyLength = 1024;

// Levenshtein distance: the "did you mean" of an unknown key.
size_t edit_distance(const std::string& a, const std::string& b);
// The 1-based line of a node, 0 for a node made by an override.
int line_of(const YAML::Node& n);
// Splits a dotted key path; every part non-empty ("a..b", ".a" and "a." are malformed).
std::vector<std::string> split_key_path(const std::string& path);
// A list index: digits only, below `size`.
bool parse_index(const std::string& text, size_t size, size_t& index);
// v / len, or v itself when it is already a unit vector to rounding.
Vec2 unit_vector(const Vec2& v, double len);
// The limits of the text and its tree (size, depth, nodes, keys), checked before anything reads a value.
void check_yaml_tree(const YAML::Node& root, const std::string& file);
// Parses one YAML document under those limits (a second document is refused with its line).
YAML::Node load_checked_yaml(const std::string& text, const std::string& file);
// A copy of a tree that keeps every node's mark (line and column: YAML::Clone's are line 1), so a
// scene read from it names the file's lines; aliased nodes stay shared (models/scene_source).
YAML::Node clone_with_marks(const YAML::Node& root);
// parse_scene on a tree load_checked_yaml returned: overrides applied to it, then read and checked.
Scene read_scene_tree(YAML::Node root, const std::string& file, const std::vector<Override>& overrides);
// The node a field path names, or its deepest ancestor in the tree.
YAML::Node locate_field(const YAML::Node& root, const std::string& field);
// Applies one override to the tree; records the nodes it created or set in `touched`.
void apply_override(YAML::Node root, const Override& o, const std::string& file,
                    std::vector<std::pair<YAML::Node, std::string>>* touched = nullptr);

// What a reading needs besides the YAML: the file for messages, and the nodes that `--set`
// overrides created or replaced, so that an error in one of them names the override.
struct Context {
  std::string file;
  std::vector<std::pair<YAML::Node, std::string>> set_by_override;  // node, override key path

  const std::string* override_of(const YAML::Node& n) const {
    for (const auto& [node, path] : set_by_override)
      if (n.IsDefined() && node.is(n)) return &path;
    return nullptr;
  }
  [[noreturn]] void fail(const YAML::Node& n, const std::string& field,
                         const std::string& msg) const {
    if (const std::string* o = override_of(n))
      throw SceneError(file, 0, "--set " + *o, field + ": " + msg);
    throw SceneError(file, line_of(n), field, msg);
  }
};

// Records where `key` of the scene was given: the node's line, or the --set override that set it.
void note_key(Scene& s, const Context& ctx, const std::string& key, const YAML::Node& n);

// A YAML mapping whose keys are checked against the allowed set; typed getters throw
// SceneError with file, line and dotted field path.
class Fields {
 public:
  Fields(const YAML::Node& node, std::string path, const Context& ctx,
         std::vector<std::string> allowed)
      : node_(node), path_(std::move(path)), ctx_(ctx), allowed_(std::move(allowed)) {
    if (!node_.IsMap()) fail_at(node_, path_, "expected a mapping of keys to values");
    for (const auto& kv : node_) {
      if (!kv.first.IsScalar()) fail_at(kv.first, path_, "a key must be a plain name, not a list or mapping");
      const std::string key = kv.first.as<std::string>();
      if (std::find(allowed_.begin(), allowed_.end(), key) != allowed_.end()) continue;
      std::string best;
      size_t best_d = 4;  // suggest only close matches
      for (const auto& a : allowed_) {
        const size_t d = edit_distance(key, a);
        if (d < best_d) best_d = d, best = a;
      }
      fail_at(ctx_.override_of(kv.second) ? kv.second : kv.first, join(key),
              best.empty() ? "unknown key" : fmt::format("unknown key (did you mean '{}'?)", best));
    }
  }

  bool has(const std::string& k) const { return static_cast<bool>(node_[k]); }
  YAML::Node raw(const std::string& k) const { return node_[k]; }
  std::string join(const std::string& k) const { return path_.empty() ? k : path_ + "." + k; }
  int line() const { return line_of(node_); }

  [[noreturn]] void fail_at(const YAML::Node& n, const std::string& field,
                            const std::string& msg) const {
    ctx_.fail(n, field, msg);
  }
  [[noreturn]] void fail(const std::string& key, const std::string& msg) const {
    fail_at(has(key) ? node_[key] : node_, join(key), msg);
  }

  YAML::Node required(const std::string& k) const {
    if (!has(k)) fail_at(node_, join(k), "missing required field");
    return node_[k];
  }

  double num(const std::string& k) const { return to_num(required(k), join(k)); }
  double num_or(const std::string& k, double def) const { return has(k) ? num(k) : def; }
  // A number given in a unit other than the scene's (degrees, hertz): checked in that unit,
  // so the message quotes what the user typed.
  double num_abs_max(const std::string& k, double def, double max, const char* unit) const {
    const double v = num_or(k, def);
    if (std::abs(v) > max)
      fail(k, fmt::format("must be finite with |value| ≤ {:g} {} (got {:g})", max, unit, v));
    return v;
  }
  double num_in(const std::string& k, double lo, double hi, const char* unit) const {
    const double v = num(k);
    if (v < lo || v > hi)
      fail(k, fmt::format("must be in [{:g}, {:g}] {} (got {:g})", lo, hi, unit, v));
    return v;
  }
  std::string str(const std::string& k) const {
    const YAML::Node n = required(k);
    if (!n.IsScalar()) fail_at(n, join(k), "expected a text value");
    return n.as<std::string>();
  }
  std::string str_or(const std::string& k, const std::string& def) const {
    return has(k) ? str(k) : def;
  }
  // A name (see is_valid_name): checked here, where the line is known.
  std::string name(const std::string& k) const {
    const std::string v = str(k);
    if (!is_valid_name(v)) fail(k, invalid_name_message(v));
    return v;
  }
  bool flag_or(const std::string& k, bool def) const {
    if (!has(k)) return def;
    const YAML::Node n = node_[k];
    bool v = false;
    if (!n.IsScalar() || !YAML::convert<bool>::decode(n, v))
      fail_at(n, join(k), "expected true or false");
    return v;
  }
  Vec2 vec2(const std::string& k) const { return to_vec2(required(k), join(k)); }

  double to_num(const YAML::Node& n, const std::string& field) const {
    if (!n.IsScalar()) fail_at(n, field, "expected a number");
    double v = 0.0;
    const std::string text = n.Scalar();
    if (!YAML::convert<double>::decode(n, v) || text.empty())
      fail_at(n, field, fmt::format("expected a number, got '{}'", text.substr(0, 40)));
    if (!std::isfinite(v))
      fail_at(n, field, fmt::format("must be finite, got '{}'", text.substr(0, 40)));
    // A nonzero literal below the smallest normal double (2.2e-308) would be read as 0 or a
    // denormal that has lost its digits: refuse it instead of silently changing the value.
    if (std::abs(v) < std::numeric_limits<double>::min()) {
      const std::string mantissa = text.substr(0, text.find_first_of("eE"));
      if (mantissa.find_first_of("123456789") != std::string::npos)
        fail_at(n, field,
                fmt::format("'{}' is too small to represent (below 2.2e-308 in magnitude); write 0 if zero is meant",
                            text.substr(0, 40)));
    }
    return v;
  }
  Vec2 to_vec2(const YAML::Node& n, const std::string& field) const {
    if (!n.IsSequence() || n.size() != 2) fail_at(n, field, "expected a pair [x, y]");
    return {to_num(n[0], field + "[0]"), to_num(n[1], field + "[1]")};
  }

  const Context& ctx() const { return ctx_; }
  const std::string& file() const { return ctx_.file; }

 private:
  YAML::Node node_;
  std::string path_;
  const Context& ctx_;
  std::vector<std::string> allowed_;
};

// Reads a list of mappings; each item must have a unique `name` unless `named` is false.
template <typename F>
void for_each_item(const Fields& parent, const std::string& key, F&& f) {
  if (!parent.has(key)) return;
  const YAML::Node seq = parent.raw(key);
  if (!seq.IsSequence()) parent.fail(key, "expected a list");
  for (size_t i = 0; i < seq.size(); ++i) f(seq[i], parent.join(key) + fmt::format("[{}]", i));
}

// Point on a body: [x, y] or the name of one of the body's (or ground's) points.
Vec2 read_point(const Fields& f, const std::string& key, const std::string& body, const Scene& s);

}  // namespace rdyn::models::yaml
