// A reduced table read without its content checksum (written before rdyn recorded one, or the
// checksum deleted together with an edit) checked against the scene it names: extracted again at
// its grid and method, and compared value for value, with its singular and pole annotations. The
// hostile pass of issue #22/#23 edited a table's values, and deleted its `# pole` line, and both
// ran with only a warning; a checksummed table needs no check (its content is what rdyn wrote
// for the scene whose hash it carries).
#pragma once

#include "models/scene.hpp"
#include "reduced/samples.hpp"

namespace rdyn::validate {

// Relative agreement asked of every value, against its column's largest magnitude: extraction
// is deterministic (a sweep's tables are byte-identical between processes), so only an edit or
// a table from another rdyn version differs; 1e-6 keeps the latter (rounding-level changes of
// the kinetostatic calls) while any edit that matters to a result is far larger.
inline constexpr double kTableCheckRelTol = 1e-6;

// Throws reduced::TableError naming the table's file and line (and the column) of the first
// value that differs, or the annotation (# singular, # pole) that was removed or changed. The
// scene is the one the table is used with (with its reaction requests, as extracted).
void check_table_against_scene(const reduced::Samples& table, const models::Scene& scene);

}  // namespace rdyn::validate
