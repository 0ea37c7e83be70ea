#include "models/yaml_fields.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <sstream>
#include <unordered_set>

namespace rdyn::models::yaml {

size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diag = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diag = up;
    }
  }
  return row[b.size()];
}


// v / len, or v itself when it is already a unit vector to rounding (|len − 1| ≤ 4 ulp):
// dividing a normalised vector by its rounded length can move it by an ulp, and a scene
// written by scene_to_yaml must read back bit for bit.
Vec2 unit_vector(const Vec2& v, double len) {
  if (std::abs(len - 1.0) <= 4 * std::numeric_limits<double>::epsilon()) return v;
  return {v.x / len, v.y / len};
}

int line_of(const YAML::Node& n) {
  const auto m = n.Mark();
  return m.is_null() ? 0 : m.line + 1;
}

namespace {

// Limits on the tree (with kMaxSceneBytes): scenes are a few hundred nodes.
// yaml-cpp recurses once per nesting level while parsing (it stops itself at 2000 levels,
// DeepRecursion) and so do the tree walks here: 64 is far more than a scene needs.
constexpr int kMaxDepth = 64;
// Aliases share nodes, so `&a [*b, *b, ...]` chains ("billion laughs") make a small text
// whose tree is exponentially large when walked; an alias to its own ancestor makes a cycle.
// Every walk over the tree is bounded by this many node visits and by kMaxDepth.
constexpr size_t kMaxTreeNodes = 200000;

// Walks the tree once: keys are unique scalars, every mapping and list has at most
// limits::kMaxItems entries, every scalar at most limits::kMaxTextLength characters, the
// nesting at most kMaxDepth and the walk (aliases expanded) at most kMaxTreeNodes visits.
void check_yaml_tree(const YAML::Node& node, const std::string& file, const std::string& path,
                     int depth, size_t& visits) {
  auto fail = [&](const YAML::Node& at, const std::string& field, const std::string& msg) {
    // A path through a cycle is as long as the depth limit allows: keep the message readable.
    throw SceneError(file, line_of(at), field.size() > 100 ? field.substr(0, 100) + "…" : field,
                     msg);
  };
  if (++visits > kMaxTreeNodes)
    fail(node, path,
         fmt::format(
             "the YAML tree has more than {} nodes (aliases expanded); a scene needs far fewer",
             kMaxTreeNodes));
  if (depth > kMaxDepth)
    fail(node, path,
         fmt::format("nested more than {} levels deep (or an alias refers to its own ancestor)",
                     kMaxDepth));
  auto child = [&](const std::string& key) { return path.empty() ? key : path + "." + key; };
  if (node.IsScalar()) {
    if (node.Scalar().size() > limits::kMaxTextLength)
      fail(node, path,
           fmt::format("a value of {} characters; at most {}", node.Scalar().size(),
                       limits::kMaxTextLength));
  } else if (node.IsSequence()) {
    if (node.size() > limits::kMaxItems)
      fail(node, path,
           fmt::format("a list of {} items; at most {}", node.size(), limits::kMaxItems));
    for (size_t i = 0; i < node.size(); ++i)
      check_yaml_tree(node[i], file, path + fmt::format("[{}]", i), depth + 1, visits);
  } else if (node.IsMap()) {
    if (node.size() > limits::kMaxItems)
      fail(node, path,
           fmt::format("a mapping of {} keys; at most {}", node.size(), limits::kMaxItems));
    std::map<std::string, int> first_line;  // key → line of its first occurrence
    for (const auto& kv : node) {
      if (!kv.first.IsScalar())
        fail(kv.first, path, "a key must be plain text, not a list or mapping");
      const std::string& key = kv.first.Scalar();
      const std::string shown = key.size() > 64 ? key.substr(0, 64) + "…" : key;
      // yaml-cpp keeps both entries of a repeated key and reads the first: refuse instead.
      const auto [it, inserted] = first_line.emplace(key, line_of(kv.first));
      if (!inserted)
        fail(kv.first, child(shown),
             fmt::format("duplicate key '{}' (first given at line {})", shown, it->second));
      check_yaml_tree(kv.second, file, child(shown), depth + 1, visits);
    }
  }
}

}  // namespace

void check_yaml_tree(const YAML::Node& root, const std::string& file) {
  size_t visits = 0;
  check_yaml_tree(root, file, "", 0, visits);
}

// Line of the `---` (or `...`) that ends the first document, the last such line before the
// second document's first node (its mark: the node, not the marker); that line itself when
// none is found.
int calc_document_marker_line(const std::string& text, int second_line) {
  int line = 1, marker = 0;
  for (size_t at = 0; at < text.size() && (second_line <= 0 || line < second_line); ++line) {
    if (text.compare(at, 3, "---") == 0 || text.compare(at, 3, "...") == 0) marker = line;
    const auto nl = text.find('\n', at);
    if (nl == std::string::npos) break;
    at = nl + 1;
  }
  return marker > 0 ? marker : second_line;
}

// Parses scene text with the limits above (size, flow nesting, NUL bytes before parsing; the
// tree after). Throws SceneError.
YAML::Node load_checked_yaml(const std::string& text, const std::string& file) {
  // Refuse anything huge before the YAML parser sees it.
  if (text.size() > kMaxSceneBytes)
    throw SceneError(
        file, 0, "",
        fmt::format("too large for a scene ({} bytes, at most {})", text.size(), kMaxSceneBytes));
  {  // flow nesting, counted conservatively (brackets inside quotes count too)
    int depth = 0, max_depth = 0;
    for (char c : text) {
      if (c == '[' || c == '{')
        max_depth = std::max(max_depth, ++depth);
      else if ((c == ']' || c == '}') && depth > 0)
        --depth;
    }
    if (max_depth > kMaxDepth)
      throw SceneError(
          file, 0, "",
          fmt::format("nested too deeply for a scene (more than {} levels of [ or {{)", kMaxDepth));
  }
  if (text.find('\0') != std::string::npos)
    throw SceneError(file, 0, "", "not a text file (contains NUL bytes)");
  YAML::Node root;
  try {
    // All documents: YAML::Load reads the first and silently drops the rest, so a scene
    // pasted after `---` would be ignored (issue #23).
    const std::vector<YAML::Node> docs = YAML::LoadAll(text);
    if (docs.size() > 1) throw SceneError(file, calc_document_marker_line(text, line_of(docs[1])), "",
                                          "a second YAML document (after '---'); a scene file holds one "
                                          "scene: remove the marker and what follows, or merge the two");
    if (!docs.empty()) root = docs.front();
  } catch (const YAML::Exception& e) {  // ParserException, DeepRecursion (block nesting)
    throw SceneError(file, e.mark.is_null() ? 0 : e.mark.line + 1, "", "malformed YAML: " + e.msg);
  }
  if (!root || root.IsNull()) throw SceneError(file, 0, "", "the scene file is empty");
  if (!root.IsMap())
    throw SceneError(file, line_of(root), "", "a scene must be a YAML mapping of keys");
  check_yaml_tree(root, file);
  return root;
}

// The node a field path names ("bodies[2].mass_kg", "loads.brake.coefficient",
// "gravity.g_m_s2[1]": map keys, list items by index or by name), or the deepest ancestor
// found when the field is not in the tree (a value derived from it, or generated).
YAML::Node locate_field(const YAML::Node& root, const std::string& field) {
  std::vector<std::string> parts;  // "a[2].b" → a, 2, b
  for (const std::string& dotted : split_key_path(field)) {
    const auto open = dotted.find('[');
    parts.push_back(dotted.substr(0, open));
    for (auto i = open; i != std::string::npos; i = dotted.find('[', i + 1))
      parts.push_back(dotted.substr(i + 1, dotted.find(']', i) - i - 1));
  }
  YAML::Node cur;
  cur.reset(root);
  YAML::Node found;  // null: nothing matched
  for (const auto& key : parts) {
    YAML::Node next;
    bool ok = false;
    if (cur.IsMap() && cur[key]) {
      next.reset(cur[key]);
      ok = true;
    } else if (cur.IsSequence()) {
      size_t idx = 0;
      if (parse_index(key, cur.size(), idx)) {
        next.reset(cur[idx]);
        ok = true;
      }
      for (size_t k = 0; k < cur.size() && !ok; ++k)
        if (cur[k].IsMap() && cur[k]["name"] && cur[k]["name"].IsScalar() &&
            cur[k]["name"].Scalar() == key) {
          next.reset(cur[k]);
          ok = true;
        }
    }
    if (!ok) break;
    cur.reset(next);
    found.reset(cur);
  }
  return found;
}


// Records where `key` of the scene was given: the node's line, or the --set override that
// set it (Scene::key_overrides), so that refusals found after loading name the right one.
void note_key(Scene& s, const Context& ctx, const std::string& key, const YAML::Node& n) {
  if (const std::string* o = ctx.override_of(n)) {
    s.key_lines.erase(key);
    s.key_overrides[key] = *o;
  } else {
    s.key_lines[key] = line_of(n);
  }
}



// Point on a body: [x, y] or the name of one of the body's (or ground's) points.
Vec2 read_point(const Fields& f, const std::string& key, const std::string& body, const Scene& s) {
  const YAML::Node n = f.required(key);
  if (n.IsSequence()) return f.to_vec2(n, f.join(key));
  if (!n.IsScalar()) f.fail(key, "expected [x, y] or the name of a point");
  const std::string name = n.as<std::string>();
  if (body == kGround) {
    auto it = s.ground_points.find(name);
    if (it != s.ground_points.end()) return it->second;
  } else if (const Body* b = s.find_body(body)) {
    auto it = b->points.find(name);
    if (it != b->points.end()) return it->second;
  }
  f.fail(key, fmt::format("body '{}' has no point named '{}'", body, name));
}

// Splits a dotted key path; every part non-empty ("a..b", ".a" and "a." are malformed).
std::vector<std::string> split_key_path(const std::string& path) {
  std::vector<std::string> parts(1);
  for (char c : path) {
    if (c == '.')
      parts.emplace_back();
    else
      parts.back() += c;
  }
  return parts;
}

// A list index: digits only, below `size`.
bool parse_index(const std::string& text, size_t size, size_t& index) {
  if (text.empty() || text.size() > 9 ||
      !std::all_of(text.begin(), text.end(), [](char c) { return c >= '0' && c <= '9'; }))
    return false;
  index = std::stoul(text);
  return index < size;
}

// Applies one override to the YAML tree; records the nodes it created or set in `touched`
// (so that a later error in them names the override).
void apply_override(YAML::Node root, const Override& o, const std::string& file,
                    std::vector<std::pair<YAML::Node, std::string>>* touched) {
  const std::vector<std::string> parts = split_key_path(o.path);
  auto fail = [&](const std::string& msg) { throw SceneError(file, 0, "--set " + o.path, msg); };
  if (std::any_of(parts.begin(), parts.end(), [](auto& p) { return p.empty(); }))
    fail("malformed key path (empty part)");
  YAML::Node cur;
  cur.reset(root);
  for (size_t i = 0; i + 1 < parts.size(); ++i) {
    const std::string& key = parts[i];
    YAML::Node next;
    if (cur.IsSequence()) {
      size_t idx = 0;
      bool found = false;
      if (parse_index(key, cur.size(), idx)) {
        next.reset(cur[idx]);
        found = true;
      } else {
        for (size_t k = 0; k < cur.size() && !found; ++k)
          if (cur[k].IsMap() && cur[k]["name"] && cur[k]["name"].IsScalar() &&
              cur[k]["name"].Scalar() == key) {
            next.reset(cur[k]);
            found = true;
          }
      }
      if (!found)
        fail(fmt::format("no list item '{}' (an index below {} or an item's name)", key,
                         cur.size()));
    } else if (cur.IsMap()) {
      if (!cur[key]) {
        cur[key] = YAML::Node(YAML::NodeType::Map);  // allows setting a generator default
        if (touched) touched->push_back({cur[key], o.path});
      }
      next.reset(cur[key]);
    } else {
      fail(fmt::format("'{}' is not a mapping or list", key));
    }
    cur.reset(next);
  }
  const std::string& last = parts.back();
  if (cur.IsSequence()) {  // e.g. one coordinate of a point: bodies.rocker.points.C.0=0.2
    size_t idx = 0;
    if (!parse_index(last, cur.size(), idx) || !cur[idx].IsScalar())
      fail(fmt::format("no scalar list item '{}' (an index below {})", last, cur.size()));
    cur[idx] = o.value;
    if (touched) touched->push_back({cur[idx], o.path});
    return;
  }
  if (!cur.IsMap()) fail("the parent of the last key is not a mapping");
  // A list of numbers written as a YAML flow list, `independent_range_deg=[95, 135]`: a scene
  // without a range could not be given one (`independent_range.0=…` has no item to set). Only
  // scalars inside, so no structure enters through --set.
  YAML::Node list;
  // A scalar key keeps its text (description=[draft]), but for `all`: outputs.joints and
  // outputs.reactions take `all` or a list, and `--set 'outputs.reactions=[crank, C]'` was refused.
  if (o.value.size() >= 2 && o.value.front() == '[' && o.value.back() == ']' &&
      !(cur[last] && cur[last].IsScalar() && cur[last].Scalar() != "all")) {
    try {
      list = YAML::Load(o.value);
    } catch (const YAML::Exception&) {
      fail("a list value is written [a, b, …] with scalar items");
    }
    if (!list.IsSequence() || list.size() > 64 ||
        std::any_of(list.begin(), list.end(), [](const YAML::Node& n) { return !n.IsScalar(); }))
      fail("a list value is written [a, b, …] with at most 64 scalar items");
    if (cur[last] && cur[last].IsMap()) fail("only scalars and lists can be set");
  } else if (cur[last] && !cur[last].IsScalar()) {
    fail("only scalar values can be set");
  }
  // The same quantity in another angle unit (q / q_deg / q_rad): the override replaces it, as the
  // user means (`--set initial.q_deg=179` on a scene giving initial.q was refused with "give q or
  // q_deg, not both", blaming the file's line).
  auto ends_with = [&](const std::string& suffix) {
    return last.size() > suffix.size() && last.compare(last.size() - suffix.size(), suffix.size(), suffix) == 0;
  };
  const std::string base = ends_with("_deg") || ends_with("_rad") ? last.substr(0, last.size() - 4) : last;
  for (const std::string& other : {base, base + "_deg", base + "_rad"})
    if (other != last && cur[other] && (cur[other].IsScalar() || cur[other].IsSequence())) cur.remove(other);
  if (list.IsSequence())
    cur[last] = list;
  else
    cur[last] = o.value;
  if (touched) {
    touched->push_back({cur[last], o.path});
    // Its items too: an error in one names the --set (it named line 1 of the scene file).
    for (size_t i = 0; list.IsSequence() && i < list.size(); ++i) touched->push_back({list[i], o.path});
  }
}

struct MarkAccess;  // names the as_if specialisation below
}  // namespace rdyn::models::yaml

namespace YAML {
// yaml-cpp keeps a node's mark (its line and column in the text) private, and YAML::Clone puts
// every node at the text's start (its NodeEvents emits each event at a default Mark, line 1:
// yaml-cpp 0.7 src/nodeevents.cpp). Node befriends every as_if<T, S>; this specialisation for a type of ours
// reads a node's identity and sets its mark through detail::node::set_mark, the call yaml-cpp's
// own NodeBuilder makes while parsing.
template <>
struct as_if<rdyn::models::yaml::MarkAccess, void> {
  static const void* identity(const Node& n) { return n.m_pNode; }
  static void set_mark(const Node& n, const Mark& mark) {
    if (n.m_pNode) n.m_pNode->set_mark(mark);
  }
};
}  // namespace YAML

namespace rdyn::models::yaml {

namespace {
using Marks = YAML::as_if<MarkAccess, void>;

// Copies the marks of `from`'s nodes (keys too) onto `to`'s, which has the same shape. A node
// shared through an alias is visited once (`seen`), so the walk is linear in the nodes of the
// text, however often aliases repeat them.
void copy_marks(const YAML::Node& from, const YAML::Node& to, std::unordered_set<const void*>& seen) {
  if (!seen.insert(Marks::identity(from)).second) return;
  Marks::set_mark(to, from.Mark());
  if (from.IsSequence()) {
    for (size_t i = 0; i < from.size(); ++i) copy_marks(from[i], to[i], seen);
  } else if (from.IsMap()) {
    auto b = to.begin();
    for (auto a = from.begin(); a != from.end() && b != to.end(); ++a, ++b) {
      copy_marks(a->first, b->first, seen);
      copy_marks(a->second, b->second, seen);
    }
  }
}
}  // namespace

YAML::Node clone_with_marks(const YAML::Node& root) {
  // YAML::Clone keeps the tree's shape, order, tags, styles and shared (aliased) nodes.
  YAML::Node copy = YAML::Clone(root);
  std::unordered_set<const void*> seen;
  copy_marks(root, copy, seen);
  return copy;
}

}  // namespace rdyn::models::yaml
