// Whether a table (Samples) was extracted from a scene: its recorded fingerprint
// (models::scene_hash) against the scene's, and when they differ, a message that names what
// differs as far as the table tells (its scene's name, its constraint lines). No Simbody.
#pragma once

#include "models/scene.hpp"
#include "reduced/samples.hpp"

namespace rdyn::reduced {

// Throws TableError (naming the table's file) when `s` records no scene or another scene's hash.
void check_samples_fit(const Samples& s, const models::Scene& scene);

}  // namespace rdyn::reduced
