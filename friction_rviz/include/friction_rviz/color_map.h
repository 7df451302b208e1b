// Colours for scalar fields (the drawing-free part of the rig's displays).
#pragma once

#include <array>
#include <string>
#include <vector>

namespace friction_rviz {

struct Rgb {
  float r = 0, g = 0, b = 0;
};

/// A value range, fixed or taken from the data, and the part of the blue–white–red map it spans.
struct Range {
  double min = 0.0;
  double max = 1.0;
  double map_from = 0.0;  ///< where `min` sits on the map: 0 blue, 0.5 white, 1 red
  double map_to = 1.0;    ///< where `max` sits
};

/// The range of `values` (finite ones); never empty. With `signed_values` (a field whose sign
/// means something, as σ_zz's compression) values that change sign get a range symmetric about 0,
/// and one-signed values keep their own range on their half of the map, short of the white kept for
/// zero: negatives blue to pale blue, positives pale red to red; an all-compressive σ_zz shows no red.
Range autoRange(const std::vector<double>& values, bool signed_values);

/// Maps `value` in `range` to a diverging blue–white–red colour (below/above the range: clamped;
/// NaN: grey). Diverging, because stresses change sign.
Rgb colorOf(double value, const Range& range);

/// The fields the slider display can colour by.
enum class Field { SigmaZZ = 0, TauXZ = 1, StressRatio = 2, VonMises = 3, Speed = 4 };
std::string fieldLabel(Field field);  ///< with its unit
/// True for fields that change sign (drawn with a range symmetric about zero).
bool signedField(Field field);

/// Per-node value of `field` from node stresses (Pa) and speeds (m/s): τ/σ is τ_xz/(−σ_zz) (the
/// shear-to-compression ratio, NaN where the node is not compressed); von Mises in plane stress. None
/// where the arrays the field reads differ in length.
std::vector<double> fieldValues(Field field, const std::vector<float>& sigma_xx, const std::vector<float>& sigma_zz,
                                const std::vector<float>& tau_xz, const std::vector<float>& speed);

/// An interface node's contact state, numbered as friction_msgs/InterfaceState's constants (checked where
/// the messages are read).
constexpr unsigned kStuck = 0, kSliding = 1, kDetached = 2;

/// Colour of an interface node by contact state: stuck blue, sliding red, contact lost grey.
Rgb contactColor(unsigned state);

}  // namespace friction_rviz
