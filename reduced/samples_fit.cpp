#include "reduced/samples_fit.hpp"

#include <string>
#include <vector>

#include <fmt/format.h>

#include "models/scene_hash.hpp"

namespace rdyn::reduced {

// A table fits only the scene it was extracted from (same mechanism, branch, grid anchor and
// load placement): compare the fingerprints before anything else.
void check_samples_fit(const Samples& s, const models::Scene& scene) {
  const std::string what = s.file.empty() ? fmt::format("the table of scene '{}'", s.scene) : "table " + s.file;
  if (!s.scene_hash)
    throw TableError(what + " does not record the scene it was extracted from; re-extract it with `rdyn extract`");
  const std::uint64_t h = models::scene_hash(scene);
  // The constraint lines (the scene's constraint forces, and the reaction lines its joint outputs
  // add) are part of a table's identity because each is a pair of columns: when those differ,
  // say so — "a different scene" sent a user who only added `reactions: all` hunting for a change
  // in the mechanism.
  // The table's header names the scene it came from: when that is another name, say so first.
  const std::string from = !s.scene.empty() && s.scene != scene.name ? fmt::format(" ('{}')", s.scene) : "";
  std::vector<std::string> has, wants;
  for (const auto& name : s.names)
    if (name.rfind("me1_", 0) == 0) has.push_back(name.substr(4));
  for (const auto& f : scene.outputs.constraint_forces) wants.push_back(f.name);
  if (*s.scene_hash != h && has != wants) {
    auto list = [](const std::vector<std::string>& v) {
      return v.empty() ? std::string("none") : fmt::format("{}", fmt::join(v, ", "));
    };
    throw TableError(fmt::format("{} was extracted from a different scene{}: it has constraint lines for {} where scene "
                                 "'{}' asks for {} (its constraint forces, and the reaction lines its outputs' "
                                 "reactions add; its mechanism may differ too: hash {} vs {}); re-extract it with "
                                 "`rdyn extract` for this scene and its outputs",
                                 what, from, list(has), scene.name, list(wants), models::scene_hash_hex(*s.scene_hash),
                                 models::scene_hash_hex(h)));
  }
  if (*s.scene_hash != h)
    throw TableError(fmt::format("{} was extracted from a different scene{} (its mechanism, where loads act, the "
                                 "constraint forces' definitions, or the initial q that picks the assembly branch "
                                 "differ: hash {} vs {}); re-extract it for scene '{}'",
                                 what, from, models::scene_hash_hex(*s.scene_hash), models::scene_hash_hex(h),
                                 scene.name));
}

}  // namespace rdyn::reduced
