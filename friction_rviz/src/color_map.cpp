#include "friction_rviz/color_map.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace friction_rviz {

Range autoRange(const std::vector<double>& values, bool signed_values) {
  double low = std::numeric_limits<double>::infinity(), high = -low;
  for (double value : values) {
    if (!std::isfinite(value)) continue;
    low = std::min(low, value);
    high = std::max(high, value);
  }
  if (!(low <= high)) return Range{};
  Range range;
  if (signed_values && low < 0.0 && high > 0.0) {
    const double extent = std::max(std::abs(low), std::abs(high));
    low = -extent;
    high = extent;
  } else if (signed_values && high <= 0.0) {
    // Short of white, which stands for zero stress: the slider stays visible on a white background.
    range.map_to = 0.3;
  } else if (signed_values) {
    range.map_from = 0.7;
  }
  if (high - low <= 0.0) {
    const double pad = std::max(std::abs(high), 1.0) * 1e-6;
    low -= pad;
    high += pad;
  }
  range.min = low;
  range.max = high;
  return range;
}

Rgb colorOf(double value, const Range& range) {
  if (std::isnan(value)) return Rgb{0.5f, 0.5f, 0.5f};
  const double s = range.map_from + (range.map_to - range.map_from) *
                                        std::clamp((value - range.min) / (range.max - range.min), 0.0, 1.0);
  // Blue (0.23, 0.30, 0.75) through white to red (0.71, 0.02, 0.15), linear in each half.
  const Rgb blue{0.23f, 0.30f, 0.75f}, white{0.95f, 0.95f, 0.95f}, red{0.71f, 0.02f, 0.15f};
  const Rgb& from = s < 0.5 ? blue : white;
  const Rgb& to = s < 0.5 ? white : red;
  const float w = static_cast<float>(s < 0.5 ? 2.0 * s : 2.0 * s - 1.0);
  return Rgb{from.r + w * (to.r - from.r), from.g + w * (to.g - from.g), from.b + w * (to.b - from.b)};
}

std::string fieldLabel(Field field) {
  switch (field) {
    case Field::SigmaZZ:
      return "sigma_zz (Pa)";
    case Field::TauXZ:
      return "tau_xz (Pa)";
    case Field::StressRatio:
      return "tau/sigma";
    case Field::VonMises:
      return "von Mises (Pa)";
    case Field::Speed:
      break;
  }
  return "speed (m/s)";
}

bool signedField(Field field) {
  return field == Field::SigmaZZ || field == Field::TauXZ || field == Field::StressRatio;
}

std::vector<double> fieldValues(Field field, const std::vector<float>& sigma_xx, const std::vector<float>& sigma_zz,
                                const std::vector<float>& tau_xz, const std::vector<float>& speed) {
  const std::size_t n = field == Field::Speed ? speed.size() : sigma_zz.size();
  if (field != Field::Speed && (sigma_xx.size() != n || tau_xz.size() != n)) return {};
  std::vector<double> out(n);
  for (std::size_t i = 0; i < n; ++i) {
    // In double: the squares of stresses of megapascals lose digits in float.
    const auto at = [i](const std::vector<float>& values) { return static_cast<double>(values[i]); };
    switch (field) {
      case Field::SigmaZZ:
        out[i] = at(sigma_zz);
        break;
      case Field::TauXZ:
        out[i] = at(tau_xz);
        break;
      case Field::StressRatio:
        out[i] = at(sigma_zz) < 0.0 ? at(tau_xz) / -at(sigma_zz) : std::numeric_limits<double>::quiet_NaN();
        break;
      case Field::VonMises:
        out[i] = std::sqrt(at(sigma_xx) * at(sigma_xx) - at(sigma_xx) * at(sigma_zz) + at(sigma_zz) * at(sigma_zz) +
                           3.0 * at(tau_xz) * at(tau_xz));
        break;
      case Field::Speed:
        out[i] = at(speed);
        break;
    }
  }
  return out;
}

Rgb contactColor(unsigned state) {
  switch (state) {
    case kStuck:
      return Rgb{0.15f, 0.35f, 0.95f};
    case kSliding:
      return Rgb{0.95f, 0.15f, 0.10f};
    default:
      return Rgb{0.55f, 0.55f, 0.55f};
  }
}

}  // namespace friction_rviz
