// Segment inertial parameters scaled from published anthropometric tables.
#pragma once

#include <string>

namespace rdyn::models {

// One segment as a fraction of the subject: mass fraction of body mass, length as a
// fraction of stature, centre of mass from the proximal end as a fraction of the
// segment length, and sagittal radius of gyration as a fraction of the segment length.
struct SegmentFractions {
  double mass;
  double length;
  double com;
  double gyration;
};

struct LowerLimbFractions {
  SegmentFractions thigh;  // hip joint centre → knee joint centre
  SegmentFractions shank;  // knee joint centre → lateral malleolus
  SegmentFractions foot;   // heel → tip of the longest toe
  double ankle_height;     // lateral malleolus above the sole, fraction of stature
};

// de Leva P. (1996) "Adjustments to Zatsiorsky–Seluyanov's segment inertia parameters",
// J. Biomech. 29(9):1223–1230, Table 4 (sex = "male" or "female"); ankle height from
// Drillis R., Contini R. (1966), Tech. Rep. 1166-03, NYU (0.039 of stature).
// Throws std::invalid_argument for another sex string.
LowerLimbFractions de_leva_1996(const std::string& sex);

}  // namespace rdyn::models
