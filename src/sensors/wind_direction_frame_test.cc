#include "sensors/wind_direction_frame.h"

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

namespace clothwind::sensors {
namespace {

constexpr double kNoDirection = std::numeric_limits<double>::quiet_NaN();

TEST(WindDirectionFrameGate, AdoptsTheFirstFrameThatComesWithADirection) {
  WindDirectionFrameGate gate;
  EXPECT_EQ(gate.frame_id(), "");
  // A calm reading (no direction) in another frame neither sets the frame nor is refused.
  EXPECT_TRUE(gate.Admit("odom", kNoDirection));
  EXPECT_EQ(gate.frame_id(), "");
  EXPECT_TRUE(gate.Admit("anemometer", 1.0));
  EXPECT_EQ(gate.frame_id(), "anemometer");
  EXPECT_TRUE(gate.Admit("anemometer", -2.0));
  EXPECT_FALSE(gate.Admit("enu", 0.5));  // true wind of MWD, in another frame
  EXPECT_TRUE(gate.Admit("enu", kNoDirection));
  EXPECT_EQ(gate.rejected(), 1u);
  EXPECT_EQ(gate.last_rejected_frame(), "enu");
  EXPECT_EQ(gate.frame_id(), "anemometer");
}

TEST(WindDirectionFrameGate, AnInfiniteDirectionNamesNoFrame) {
  // A broken instrument's first reading with direction +inf locked every clip's direction frame
  // to its frame (and their mean to NaN).
  WindDirectionFrameGate gate;
  EXPECT_TRUE(gate.Admit("bogus", std::numeric_limits<double>::infinity()));
  EXPECT_EQ(gate.frame_id(), "");
  EXPECT_TRUE(gate.Admit("anemometer", 0.5));
  EXPECT_EQ(gate.frame_id(), "anemometer");
  EXPECT_TRUE(gate.Admit("bogus", -std::numeric_limits<double>::infinity()));  // no direction: no refusal
  EXPECT_EQ(gate.rejected(), 0u);
}

TEST(WindDirectionFrameGate, AcceptsAsksWithoutAdoptingOrCounting) {
  WindDirectionFrameGate gate;
  EXPECT_TRUE(gate.Accepts("enu", 1.0));  // any frame while none is adopted...
  EXPECT_EQ(gate.frame_id(), "");         // ...and asking adopts none
  EXPECT_TRUE(gate.Admit("anemometer", 1.0));
  EXPECT_FALSE(gate.Accepts("enu", 1.0));
  EXPECT_TRUE(gate.Accepts("enu", kNoDirection));
  EXPECT_TRUE(gate.Accepts("anemometer", 0.5));
  EXPECT_EQ(gate.rejected(), 0u);
}

TEST(WindDirectionFrameGate, AFixedFrameRefusesEveryOtherOneFromTheStart) {
  WindDirectionFrameGate gate("enu");
  EXPECT_FALSE(gate.Admit("anemometer", 1.0));
  EXPECT_TRUE(gate.Admit("enu", 1.0));
  EXPECT_FALSE(gate.Admit("", 1.0));  // an unnamed frame is not "enu"
  EXPECT_EQ(gate.rejected(), 2u);
  EXPECT_EQ(gate.frame_id(), "enu");
}

TEST(WindDirectionFrameGate, AnUnnamedFirstFrameIsKeptAsUnnamed) {
  // A driver that leaves frame_id empty is one frame; a named one after it is another.
  WindDirectionFrameGate gate;
  EXPECT_TRUE(gate.Admit("", 0.1));
  EXPECT_TRUE(gate.Admit("", 0.2));
  EXPECT_FALSE(gate.Admit("anemometer", 0.3));
}

}  // namespace
}  // namespace clothwind::sensors
