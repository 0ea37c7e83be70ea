#include "models/anthropometry.hpp"

#include <stdexcept>

namespace rdyn::models {

LowerLimbFractions de_leva_1996(const std::string& sex) {
  // Table 4 gives segment lengths in mm for the reference subjects: stature 1741 mm
  // (male, 73.0 kg) and 1735 mm (female, 61.9 kg); lengths are divided by those statures.
  // Longitudinal CoM positions and sagittal radii of gyration are % of segment length.
  const double kDrillisAnkleHeight = 0.039;
  if (sex == "male") {
    return {{0.1416, 422.2 / 1741.0, 0.4095, 0.329},
            {0.0433, 434.0 / 1741.0, 0.4459, 0.255},
            {0.0137, 258.1 / 1741.0, 0.4415, 0.257},
            kDrillisAnkleHeight};
  }
  if (sex == "female") {
    return {{0.1478, 369.8 / 1735.0, 0.3612, 0.369},
            {0.0481, 432.3 / 1735.0, 0.4352, 0.267},
            {0.0129, 228.3 / 1735.0, 0.4014, 0.299},
            kDrillisAnkleHeight};
  }
  throw std::invalid_argument("sex must be 'male' or 'female' (de Leva 1996 tables)");
}

}  // namespace rdyn::models
