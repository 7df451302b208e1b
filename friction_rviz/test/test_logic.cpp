// The drawing-free logic of the rviz plugins: colours, bounded histories, time jumps, commands.
#include <gtest/gtest.h>

#include <friction_msgs/SlipEvent.h>
#include <cmath>

#include "friction_rviz/color_map.h"
#include "friction_rviz/commands.h"
#include "friction_rviz/history.h"

namespace friction_rviz {
namespace {

TEST(ColorMap, DivergingFromBlueThroughWhiteToRedAndClamped) {
  const Range range{-2.0, 2.0};
  const Rgb low = colorOf(-2.0, range), mid = colorOf(0.0, range), high = colorOf(2.0, range);
  EXPECT_GT(low.b, low.r);
  EXPECT_GT(high.r, high.b);
  EXPECT_NEAR(mid.r, 0.95f, 1e-6);
  EXPECT_NEAR(mid.g, 0.95f, 1e-6);
  EXPECT_EQ(colorOf(-10.0, range).b, low.b);  // clamped
  EXPECT_EQ(colorOf(10.0, range).r, high.r);
  EXPECT_FLOAT_EQ(colorOf(std::nan(""), range).g, 0.5f);
}

TEST(ColorMap, AutomaticRangeIsSymmetricForSignedFields) {
  const Range symmetric = autoRange({-1.0, 3.0, std::nan("")}, true);
  EXPECT_DOUBLE_EQ(symmetric.min, -3.0);
  EXPECT_DOUBLE_EQ(symmetric.max, 3.0);
  // All compressive: its own range, on the blue side from full blue to 60 % of the way to white.
  const Range one_signed = autoRange({-3.0, -1.0}, true);
  EXPECT_DOUBLE_EQ(one_signed.min, -3.0);
  EXPECT_DOUBLE_EQ(one_signed.max, -1.0);
  const Rgb most = colorOf(-3.0, one_signed), least = colorOf(-1.0, one_signed), middle = colorOf(-2.0, one_signed);
  EXPECT_FLOAT_EQ(most.r, 0.23f);
  EXPECT_FLOAT_EQ(most.b, 0.75f);
  EXPECT_FLOAT_EQ(least.r, 0.23f + 0.6f * (0.95f - 0.23f));
  EXPECT_FLOAT_EQ(least.b, 0.75f + 0.6f * (0.95f - 0.75f));
  EXPECT_FLOAT_EQ(middle.r, 0.23f + 0.3f * (0.95f - 0.23f));
  // All tensile: from 40 % of the way from white to red, to red.
  const Range tensile = autoRange({1.0, 3.0}, true);
  EXPECT_FLOAT_EQ(colorOf(1.0, tensile).g, 0.95f + 0.4f * (0.02f - 0.95f));
  EXPECT_FLOAT_EQ(colorOf(3.0, tensile).r, 0.71f);
  const Range plain = autoRange({1.0, 3.0}, false);
  EXPECT_DOUBLE_EQ(plain.min, 1.0);
  EXPECT_DOUBLE_EQ(plain.max, 3.0);
  const Range flat = autoRange({2.0, 2.0}, false);
  EXPECT_LT(flat.min, flat.max);
}

TEST(ColorMap, FieldValuesFromNodeStresses) {
  const std::vector<float> sxx{0.0f, 1e6f}, szz{-2e6f, 1e6f}, txz{5e5f, 0.0f}, speed{0.1f, 0.2f};
  const auto ratio = fieldValues(Field::StressRatio, sxx, szz, txz, speed);
  EXPECT_DOUBLE_EQ(ratio[0], 0.25);
  EXPECT_TRUE(std::isnan(ratio[1]));  // not compressed
  const auto mises = fieldValues(Field::VonMises, sxx, szz, txz, speed);
  EXPECT_NEAR(mises[0], std::sqrt(4e12 + 3 * 25e10), 1e-3);
  EXPECT_NEAR(mises[1], 1e6, 1e-6);  // equibiaxial: sqrt(1 - 1 + 1)·σ
  const auto speeds = fieldValues(Field::Speed, sxx, szz, txz, speed);
  EXPECT_EQ(speeds, std::vector<double>(speed.begin(), speed.end()));
  // Stress arrays of different lengths (a foreign or truncated snapshot) give none, not a read past one.
  EXPECT_TRUE(fieldValues(Field::VonMises, {0.0f}, szz, txz, speed).empty());
  EXPECT_EQ(fieldValues(Field::Speed, {0.0f}, szz, txz, speed).size(), 2u);
  EXPECT_TRUE(signedField(Field::TauXZ));
  EXPECT_FALSE(signedField(Field::Speed));
}

TEST(History, SeriesKeepsAtMostItsCapacityAndClearsWhenTimeJumpsBack) {
  SeriesHistory history(3);
  for (int i = 0; i < 5; ++i) EXPECT_FALSE(history.add(i, 10.0 * i));
  ASSERT_EQ(history.times().size(), 3u);
  EXPECT_DOUBLE_EQ(history.times().front(), 2.0);
  EXPECT_TRUE(history.add(0.5, 1.0));
  ASSERT_EQ(history.times().size(), 1u);
  EXPECT_DOUBLE_EQ(history.values().front(), 1.0);
}

TEST(History, PrecursorPlotTellsSingleNodeSlipsPrecursorsBackSlipsGlobalEventsAndLaterCycles) {
  using Kind = friction_msgs::SlipEvent;
  PrecursorScatter scatter;
  scatter.add(192.0, 1920.0, 0.0, 0.14, Kind::SINGLE_NODE_SLIP);  // one node alone
  scatter.add(276.0, 1920.0, 0.035, 0.14, Kind::PRECURSOR);       // a precursor a quarter of the slider long
  scatter.add(100.0, 0.0, 0.01, 0.14, Kind::PRECURSOR);           // no normal load: no F_X/F_Z to plot
  scatter.add(68.0, 1920.0, 0.0275, 0.14, Kind::BACK_SLIP);       // the stage drew back: the interface slid back
  scatter.add(399.0, 1920.0, 0.14, 0.14, Kind::GLOBAL);
  scatter.add(353.0, 1920.0, 0.0875, 0.14, Kind::AFTER_GLOBAL);  // arrested in the next stick–slip cycle
  scatter.add(96.0, 1920.0, 0.0, 0.14, Kind::AFTER_GLOBAL);      // so is a single node after the global slip
  scatter.add(96.0, 1920.0, 0.0, 0.14, 5);                       // no such kind: not drawn
  const auto& single = scatter.points(EventKind::SingleNodeSlip);
  const auto& precursors = scatter.points(EventKind::Precursor);
  const auto& global = scatter.points(EventKind::Global);
  const auto& later = scatter.points(EventKind::AfterGlobal);
  const auto& back = scatter.points(EventKind::BackSlip);
  ASSERT_EQ(back.shear_ratio.size(), 1u);
  EXPECT_DOUBLE_EQ(back.length_ratio[0], 0.0275 / 0.14);
  ASSERT_EQ(single.shear_ratio.size(), 1u);
  EXPECT_DOUBLE_EQ(single.shear_ratio[0], 0.1);
  EXPECT_DOUBLE_EQ(single.length_ratio[0], 0.0);
  ASSERT_EQ(precursors.shear_ratio.size(), 1u);
  EXPECT_DOUBLE_EQ(precursors.shear_ratio[0], 0.14375);
  EXPECT_DOUBLE_EQ(precursors.length_ratio[0], 0.25);
  ASSERT_EQ(global.length_ratio.size(), 1u);
  EXPECT_DOUBLE_EQ(global.length_ratio[0], 1.0);
  ASSERT_EQ(later.length_ratio.size(), 2u);
  EXPECT_DOUBLE_EQ(later.shear_ratio[0], 353.0 / 1920.0);
  EXPECT_DOUBLE_EQ(later.length_ratio[0], 0.625);
  EXPECT_DOUBLE_EQ(later.length_ratio[1], 0.0);
  scatter.clear();  // time jumped back
  EXPECT_TRUE(scatter.points(EventKind::Global).shear_ratio.empty());
}

TEST(History, SpaceTimeStripOutlinesEventsWithTheirSlippedRange) {
  SpaceTimeHistory strip(4);
  const std::vector<double> x{0.0, 0.01, 0.02, 0.03};
  const std::vector<double> v{0, 0, 0, 0};
  strip.add(0.0, x, v, {0, 0, 0, 0});
  strip.add(0.1, x, v, {1, 0, 0, 0});
  strip.add(0.2, x, v, {1, 1, 0, 0});
  strip.add(0.3, x, v, {0, 0, 0, 0});
  auto events = strip.visibleEvents();
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].first_row, 1u);
  EXPECT_EQ(events[0].last_row, 3u);
  EXPECT_DOUBLE_EQ(events[0].x_min, 0.0);
  EXPECT_DOUBLE_EQ(events[0].x_max, 0.01);  // L_p = 10 mm
  EXPECT_TRUE(events[0].ended);
  // Scrolling: older rows leave, the event's indices follow, and it goes once wholly out of view.
  strip.add(0.4, x, v, {0, 0, 0, 0});
  events = strip.visibleEvents();
  ASSERT_EQ(strip.size(), 4u);
  EXPECT_EQ(events[0].first_row, 0u);
  EXPECT_EQ(events[0].last_row, 2u);
  for (double t : {0.5, 0.6, 0.7}) strip.add(t, x, v, {0, 0, 0, 0});
  EXPECT_TRUE(strip.visibleEvents().empty());
  EXPECT_TRUE(strip.add(0.05, x, v, {0, 0, 0, 0}));  // looped playback
  EXPECT_EQ(strip.size(), 1u);
}

TEST(Commands, PanelUnitsBecomeSiCommandsAppliedNow) {
  const auto drive = driveCommand(0.4);
  EXPECT_EQ(drive.mode, friction_msgs::StageCommand::VELOCITY);
  EXPECT_DOUBLE_EQ(drive.speed, 4e-4);
  EXPECT_TRUE(drive.header.stamp.isZero());
  EXPECT_EQ(holdCommand().mode, friction_msgs::StageCommand::HOLD);
  const auto move = moveCommand(0.2, 1.0);
  EXPECT_EQ(move.mode, friction_msgs::StageCommand::POSITION);
  EXPECT_DOUBLE_EQ(move.target, 2e-4);
  EXPECT_DOUBLE_EQ(move.speed, 1e-3);
  const auto load = normalLoadCommand(1.92);
  EXPECT_EQ(load.mode, friction_msgs::StageCommand::NORMAL_LOAD);
  EXPECT_DOUBLE_EQ(load.normal_force, 1920.0);
  EXPECT_EQ(replyText(true, false, "speed 5 m/s exceeds the stage's max_speed 1 m/s"),
            "refused: speed 5 m/s exceeds the stage's max_speed 1 m/s");
  EXPECT_EQ(replyText(true, true, ""), "accepted");
  EXPECT_NE(replyText(false, false, "").find("no reply"), std::string::npos);
}

}  // namespace
}  // namespace friction_rviz
