// Axis ticks shared by the plot writers: nice steps, tick values and labels, against hand values.
#include <gtest/gtest.h>

#include "renderer/plot/plot_axis.h"

using namespace ofl;

TEST(PlotAxis, NiceStepIsTheSmallestOneTwoTwoAndAHalfOrFiveTimesAPowerOfTen) {
  EXPECT_DOUBLE_EQ(nice_tick_step(1.0, 5), 0.2);     // raw 0.2
  EXPECT_DOUBLE_EQ(nice_tick_step(1.0, 6), 0.2);     // raw 0.167
  EXPECT_DOUBLE_EQ(nice_tick_step(1.1, 5), 0.25);    // raw 0.22
  EXPECT_DOUBLE_EQ(nice_tick_step(300.0, 4), 100.0); // raw 75
  EXPECT_DOUBLE_EQ(nice_tick_step(0.0, 4), 1.0);
  EXPECT_DOUBLE_EQ(nice_tick_step(NAN, 4), 1.0);
}

TEST(PlotAxis, TicksAreExactMultiplesInsideTheRange) {
  auto t = axis_ticks(-0.05, 0.62, 0.1);
  ASSERT_EQ(t.size(), 7u);  // 0, 0.1, ..., 0.6
  EXPECT_DOUBLE_EQ(t.front(), 0.0);
  EXPECT_DOUBLE_EQ(t.back(), 6 * 0.1);
  // Ends that fall on a tick up to rounding are kept; many steps do not drift.
  auto u = axis_ticks(0.0, 1000 * 0.001, 0.001);
  EXPECT_EQ(u.size(), 1001u);
  EXPECT_TRUE(axis_ticks(1, 0, 0.1).empty());
}

TEST(PlotAxis, LabelsCarryTheDecimalsTheStepNeeds) {
  EXPECT_EQ(tick_label(0.5, 0.25), "0.50");
  EXPECT_EQ(tick_label(0.75, 0.25), "0.75");
  EXPECT_EQ(tick_label(400, 50), "400");
  EXPECT_EQ(tick_label(0.3, 0.1), "0.3");
  EXPECT_EQ(tick_label(-1e-18, 0.1), "0.0");
  EXPECT_EQ(tick_label(2e5, 1e5), "2e+05");
}
