// Sound (seed 2.2.10, eqs. 2.12/2.13, Table 2.11): per-microphone amplitude from the other robots'
// speakers within the microphone band, total perceived amplitude, 10 % noise.
#include <gtest/gtest.h>

#include <cmath>

#include "sbot_sim/core/sensors/sound.h"
#include "sim_fixture.h"

namespace sbot::test {
namespace {

using namespace sbot::sensors;

TEST(SoundModel, Equation212And213) {
  const double p0 = 0.25;
  EXPECT_DOUBLE_EQ(soundAmplitudeTerm(0, 0, p0), 1.0);
  EXPECT_DOUBLE_EQ(soundAmplitudeTerm(M_PI, 0, p0), 0.1);        // from behind: 1 - 0.9
  EXPECT_DOUBLE_EQ(soundAmplitudeTerm(M_PI / 2, 0, p0), 0.55);
  EXPECT_DOUBLE_EQ(soundAmplitudeTerm(0, 0.5, p0), 0.5);         // D^2 = p0 halves it
  EXPECT_NEAR(soundAmplitudeTerm(0, 2.0, p0), 1.0 / 17, 1e-12);
  EXPECT_DOUBLE_EQ(totalPerceivedAmplitude(0), 0.0);
  EXPECT_NEAR(totalPerceivedAmplitude(1.0), std::tanh(0.5), 1e-12);
  EXPECT_LT(totalPerceivedAmplitude(20.0), 1.0);
  EXPECT_GT(totalPerceivedAmplitude(20.0), 0.999);
}

struct Pair {
  World world{flatWorld(9)};
  Environment env{world};
  Robot* a = nullptr;
  Robot* b = nullptr;
  Pair() {
    a = &world.addRobot(loadLevel("medium"), {0, 0, 0}, "a");
    b = &world.addRobot(loadLevel("medium"), {0.5, 0, M_PI}, "b");
  }
  // Eq. 2.12 for microphone `mic` of a and a source at b's turret frame.
  double expected(int mic, double intensity = 1.0) const {
    const Pose m = a->linkPose("mic_" + std::to_string(mic));
    const Vec3 v = b->linkPose("turret").position - m.position;
    const double alpha = std::acos((m.orientation * Vec3::UnitX()).dot(v.normalized()));
    return intensity * soundAmplitudeTerm(alpha, v.norm(), 0.25);
  }
};

TEST(SoundSensors, AmplitudePerMicrophoneFromTheOtherRobotsSpeaker) {
  Pair p;
  SoundSensors sound(p.world, *p.a, p.env);
  for (int m = 0; m < kMicrophones; ++m) EXPECT_EQ(sound.rawAmplitude(m), 0.0) << "silence";
  p.env.setSpeaker("b", 1000, 1.0);
  // mic_0 faces b (alpha ~ 0, D ~ 0.485 m): ~0.515; mic_1/mic_2 at +-120 deg: 0.4 of that.
  EXPECT_NEAR(sound.rawAmplitude(0), p.expected(0), 1e-12);
  EXPECT_NEAR(sound.rawAmplitude(0), 1 / (1 + 0.485 * 0.485 / 0.25), 0.01);
  for (int m = 1; m < 3; ++m) {
    EXPECT_NEAR(sound.rawAmplitude(m), p.expected(m), 1e-12);
    EXPECT_NEAR(sound.rawAmplitude(m) / sound.rawAmplitude(0), 0.4, 0.03);
  }
  // Noisy reads: uniform +-10 % around the amplitude; the TPA is the sigmoid of that.
  double lo = 1e9, hi = 0;
  for (int i = 0; i < 300; ++i) {
    const double amp = sound.amplitude(0);
    lo = std::min(lo, amp);
    hi = std::max(hi, amp);
  }
  EXPECT_GE(lo, 0.9 * p.expected(0) - 1e-12);
  EXPECT_LE(hi, 1.1 * p.expected(0) + 1e-12);
  EXPECT_GT(hi - lo, 0.15 * p.expected(0));
  const double tpa = sound.read(0);
  EXPECT_GE(tpa, totalPerceivedAmplitude(0.9 * p.expected(0)));
  EXPECT_LE(tpa, totalPerceivedAmplitude(1.1 * p.expected(0)));
  // Intensity scales the source.
  p.env.setSpeaker("b", 1000, 0.5);
  EXPECT_NEAR(sound.rawAmplitude(0), 0.5 * p.expected(0), 1e-12);
}

TEST(SoundSensors, OwnSpeakerAndOutOfBandSourcesAreNotHeard) {
  Pair p;
  SoundSensors sound(p.world, *p.a, p.env);
  p.env.setSpeaker("a", 1000, 1.0);
  for (int m = 0; m < kMicrophones; ++m) EXPECT_EQ(sound.rawAmplitude(m), 0.0);
  p.env.setSpeaker("b", 50, 1.0);  // below the default 100 Hz .. 10 kHz band
  EXPECT_EQ(sound.rawAmplitude(0), 0.0);
  sound.params().band_low = 20;
  sound.params().band_high = 200;
  EXPECT_NEAR(sound.rawAmplitude(0), p.expected(0), 1e-12);
  p.env.stopSpeaker("b");
  EXPECT_EQ(sound.rawAmplitude(0), 0.0);
  EXPECT_EQ(sound.read(0), 0.0);
}

TEST(SoundSensors, SourcesAddAndFallOffWithDistance) {
  Pair p;
  Robot& c = p.world.addRobot(loadLevel("medium"), {-1.0, 0, 0}, "c");
  SoundSensors sound(p.world, *p.a, p.env);
  p.env.setSpeaker("b", 2000, 1.0);
  const double from_b = sound.rawAmplitude(0);
  p.env.setSpeaker("c", 3000, 1.0);
  const double both = sound.rawAmplitude(0);
  const Pose m = p.a->linkPose("mic_0");
  const Vec3 v = c.linkPose("turret").position - m.position;
  const double from_c = soundAmplitudeTerm(std::acos((m.orientation * Vec3::UnitX()).dot(v.normalized())), v.norm(), 0.25);
  EXPECT_NEAR(both, from_b + from_c, 1e-12);
  EXPECT_LT(from_c, 0.03) << "1 m behind: 0.1 x 1/(1 + 4)";
}

}  // namespace
}  // namespace sbot::test
