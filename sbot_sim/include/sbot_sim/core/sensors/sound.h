// Sound (seed 2.2.10, Table 2.11): 3 microphones (frames mic_0..mic_2 at the base of the camera
// pole, 120 deg apart, +x outward) and one speaker per robot (Environment::setSpeaker: one
// frequency at one intensity at a time). Frequency-based, not wave-based (the seed: a 10 ms step
// could only carry 50 Hz).
//
// Amplitude at microphone m (seed eq. 2.12), summed over the speakers s of the OTHER robots that are
// on and whose frequency lies in the microphone band [band_low, band_high]:
//
//   A_m = sum_s  I_s (1 - 0.9 alpha_s / pi) / (1 + D_s^2 / p0)
//
//   alpha_s  angle [rad, 0..pi] between the microphone's +x and the direction mic -> source,
//   D_s      distance mic -> source [m],
//   I_s      the speaker's relative intensity (1 = nominal); eq. 2.12 has no intensity term, which
//            is I_s = 1 (the seed's speaker is "binary"); we scale linearly so quieter speakers can
//            be modelled,
//   p0       CHOICE p0 = 0.25 m^2: the seed takes the law from another project's publication
//            without giving p0; 0.25 m^2 halves a source's amplitude at D = 0.5 m, i.e. about two
//            body lengths (neighbours in a swarm-bot are 15-50 cm apart) and leaves 6 % at 2 m,
//            so a robot hears its neighbourhood, not the whole arena.
//   band     CHOICE [100, 10000] Hz by default (a small speaker/electret microphone pair; the seed
//            gives "lower and upper frequency limits can be set" and no values); settable.
// The source position is the other robot's `speaker` link if it has one, else its `turret` frame
// (the speaker sits in the turret), else base_link.
//
// Total perceived amplitude (eq. 2.13) at microphone m: TPA_m = 2 / (1 + exp(-A_m)) - 1, in [0,1)
// (the seed writes an outer sum over s; with A_m already summed over the sources, as its text
// explains, the sigmoid is applied once to the sum).
// Noise: uniform 10 % (Table 2.11) on A_m, robot stream "sound", after the effects; TPA uses the
// noisy A_m. Effects see channel "sound", index = microphone, value = A_m.
// There is no sbot.h read function (the seed mentions a planned int getIntensity(k), k = 1..3);
// the SensorSuite exposes the TPA per microphone as double.
#pragma once

#include <array>
#include <string>

#include "sbot_sim/core/link_ref.h"
#include "sbot_sim/core/sensors/environment.h"
#include "sbot_sim/core/types.h"

namespace sbot {

class World;
class Robot;

namespace sensors {

constexpr int kMicrophones = 3;

struct SoundParams {
  double p0 = 0.25;           ///< [m^2] eq. 2.12 distance scale
  double band_low = 100.0;    ///< [Hz]
  double band_high = 10000.0; ///< [Hz]
  double noise = 0.1;         ///< Table 2.11
};

/// One source's term of eq. 2.12 (without the intensity factor).
double soundAmplitudeTerm(double alpha, double distance, double p0);
/// Eq. 2.13: 2 / (1 + exp(-amplitude)) - 1.
double totalPerceivedAmplitude(double amplitude);

class SoundSensors {
 public:
  SoundSensors(World& world, Robot& robot, const Environment& env);

  /// Noise-free, effect-free eq. 2.12 amplitude at microphone `mic` (0..2).
  double rawAmplitude(int mic) const;
  /// Noisy amplitude A_m (eq. 2.12 after effects and noise).
  double amplitude(int mic);
  /// Noisy total perceived amplitude (eq. 2.13) at each microphone, in [0,1].
  std::array<double, kMicrophones> readAll();
  double read(int mic) { return totalPerceivedAmplitude(amplitude(mic)); }

  SoundParams& params() { return params_; }
  const SoundParams& params() const { return params_; }

 private:
  World& world_;
  Robot& robot_;
  const Environment& env_;
  SoundParams params_;
  std::array<LinkRef, kMicrophones> links_;
};

}  // namespace sensors
}  // namespace sbot
