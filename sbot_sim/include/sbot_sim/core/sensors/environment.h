// The sensed environment of one World: what sensors perceive but ODE does not simulate.
//
//   * lamps  — isotropic point light sources (seed 2.4.2, Table 2.14): position [m], luminous
//              intensity [mcd] (milli-candela, the seed's light unit), colour (RGB in [0,1], seen
//              by the fake camera). Settable at run time like the seed's VortexWorld
//              (setLampIntensity / getLampIntensity / setAmbientLight / getAmbientLight).
//   * ambient light — one constant illuminance [mcd/cm^2] added to every light sensor
//              (2.4.2 "ambient light is modeled by adding a constant value"); it is not shadowed
//              and not weighted by the sensor's angular sensitivity.
//   * per robot: the light ring (2.2.8, Table 2.10: 8 LED groups x RGB in [0,15] units of 0.8 mcd,
//              each with a BLINKING_RATE_xx code of sbot.h) and the speaker (2.2.10: one frequency
//              [Hz] at one intensity at a time).
//   * climate — world temperature [deg C] and relative humidity [%] (2.2.11; the seed does not
//              model them, we give them a world value, see climate.h for the sensors).
//
// One Environment per World, kept by the caller (simulator node, tools, tests) next to the World;
// it keeps a reference to the World only to read the simulated time (blink phase, humidity log).
// Robots are identified by name (World robot names are unique). Not thread-safe.
#pragma once

#include <array>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "sbot_sim/core/link_ref.h"
#include "sbot_sim/core/types.h"

namespace sbot {

class World;

namespace sensors {

/// sbot.h blinking-rate codes (seed Appendix A).
enum BlinkingRate : unsigned {
  BLINKING_RATE_NO_BLINK = 0,
  BLINKING_RATE_10 = 1,    ///< 10 Hz   (period 0.1 s)
  BLINKING_RATE_5 = 2,     ///< 5 Hz    (0.2 s)
  BLINKING_RATE_3_3 = 3,   ///< 3.3 Hz  (0.3 s)
  BLINKING_RATE_2_5 = 4,   ///< 2.5 Hz  (0.4 s)
  BLINKING_RATE_2 = 5,     ///< 2 Hz    (0.5 s)
  BLINKING_RATE_1 = 6,     ///< 1 Hz    (1 s)
  BLINKING_RATE_0_5 = 7,   ///< 0.5 Hz  (2 s)
  BLINKING_RATE_0_33 = 8,  ///< 0.33 Hz (3 s)
  BLINKING_RATE_0_25 = 9,  ///< 0.25 Hz (4 s)
  BLINKING_RATE_0_2 = 10,  ///< 0.2 Hz  (5 s)
};

/// Blink period [s] of a BLINKING_RATE_xx code; 0 for NO_BLINK. Throws std::out_of_range for an
/// unknown code. The codes name rounded frequencies; the periods are the round numbers behind them
/// (3.3 Hz = 0.3 s, 0.33 Hz = 3 s).
double blinkPeriod(unsigned blink_code);

constexpr int kLedGroups = 8;        ///< Table 2.10
constexpr unsigned kLedMaxUnits = 15;///< Table 2.10: 12 mcd = 15 units
constexpr double kLedUnitMcd = 0.8;  ///< Table 2.10: [mcd] per LED unit

/// One LED group of the light ring: one red, one green and one blue LED.
struct LedGroup {
  unsigned r = 0, g = 0, b = 0;   ///< [0,15] units of 0.8 mcd (clamped on set)
  unsigned blink = BLINKING_RATE_NO_BLINK;
  double since = 0;               ///< simulated time [s] the colour/blink was set (blink phase origin)
  bool on() const { return r + g + b > 0; }
};

/// The links light_0 .. light_7: where a ring's groups sit on its robot.
std::array<LinkRef, kLedGroups> ledGroupFrames();

/// The light ring of one robot.
struct LedRing {
  std::array<LedGroup, kLedGroups> groups{};
  /// Each group's link on the robot, looked up once per build of it (LinkRef): every camera and
  /// light sensor of a lit swarm reads every other robot's ring.
  std::array<LinkRef, kLedGroups> frames = ledGroupFrames();
  /// Whether `group` emits light at simulated `time` [s]: its colour is not black and, if it
  /// blinks, `time` falls in the first half of a blink period counted from when it was set (50 %
  /// duty cycle, lit first). The hardware maximum 10 Hz (BLINKING_RATE_10) is supported (the
  /// seed's simulator stopped at 5 Hz, Table 2.10); note that a step longer than 0.05 s (Fast: 0.1
  /// s) samples a 10 Hz blink always in the same phase.
  bool isLit(int group, double time) const;
  bool anyOn() const;
};

/// The speaker of one robot (2.2.10): "limited to emit sound of a certain intensity at one single
/// frequency at a time".
struct Speaker {
  bool on = false;
  double frequency = 0;  ///< [Hz]
  double intensity = 0;  ///< relative source amplitude [-], 1 = nominal (multiplies eq. 2.12)
};

/// A world lamp (2.4.2): isotropic point source.
struct Lamp {
  Vec3 position = Vec3::Zero();  ///< [m], world frame
  double intensity = 0;          ///< [mcd] luminous intensity (>= 0)
  Vec3 colour = Vec3::Ones();    ///< RGB in [0,1] (fake camera)
};

class Environment {
 public:
  explicit Environment(const World& world);

  double time() const;  ///< the World's simulated time [s]

  // ---- lamps and ambient light (seed VortexWorld interface) ------------------------------------
  /// Add a lamp; returns its number (0, 1, ...). Intensity [mcd] must be >= 0.
  int addLamp(const Vec3& position, double intensity_mcd, const Vec3& colour = Vec3::Ones());
  void setLampIntensity(int nr, double intensity_mcd);  ///< throws std::out_of_range, invalid_argument
  double getLampIntensity(int nr) const;                 ///< [mcd]; throws std::out_of_range
  void setLampPosition(int nr, const Vec3& position);
  const std::vector<Lamp>& lamps() const { return lamps_; }
  void setAmbientLight(double illuminance_mcd_cm2);      ///< [mcd/cm^2] >= 0
  double getAmbientLight() const { return ambient_; }

  // ---- light rings (sbot.h setLightColor / setAllLightColor / setSameLightColor) ----------------
  /// Set one LED group of `robot`. Colours are clamped to [0,15]; throws std::out_of_range for a
  /// group outside [0,7] or an unknown blink code. The blink phase restarts now.
  void setLightColor(const std::string& robot, int group, unsigned r, unsigned g, unsigned b,
                     unsigned blink);
  void setAllLightColor(const std::string& robot, const std::array<unsigned, kLedGroups>& r,
                        const std::array<unsigned, kLedGroups>& g,
                        const std::array<unsigned, kLedGroups>& b,
                        const std::array<unsigned, kLedGroups>& blink);
  void setSameLightColor(const std::string& robot, unsigned r, unsigned g, unsigned b, unsigned blink);
  /// The light ring of `robot` (all groups off if never set).
  const LedRing& ledRing(const std::string& robot) const;
  bool isLit(const std::string& robot, int group, double time) const;

  // ---- speakers ----------------------------------------------------------------------------------
  /// Start emitting at `frequency_hz` (> 0) with relative `intensity` (>= 0).
  void setSpeaker(const std::string& robot, double frequency_hz, double intensity);
  void stopSpeaker(const std::string& robot);
  const Speaker& speaker(const std::string& robot) const;

  /// Forget a robot's light ring and speaker (call when it is removed from the World).
  void forgetRobot(const std::string& robot);
  /// Names of robots with a ring or speaker state (for iteration by sensors).
  const std::map<std::string, LedRing>& ledRings() const { return rings_; }
  const std::map<std::string, Speaker>& speakers() const { return speakers_; }

  // ---- climate -----------------------------------------------------------------------------------
  void setTemperature(double celsius) { temperature_ = celsius; }
  double temperature() const { return temperature_; }   ///< [deg C], default 22
  /// Set the world relative humidity [%] from now on (clamped to [0,100]); logged with the time so
  /// lagging humidity sensors (climate.h) can integrate exactly without a per-step update.
  void setHumidity(double percent);
  double humidity() const { return humidity_log_.back().second; }  ///< [%], default 45
  /// (time [s], value [%]) of every humidity change, oldest first; the first entry is at -inf.
  const std::vector<std::pair<double, double>>& humidityLog() const { return humidity_log_; }

 private:
  LedRing& ring(const std::string& robot);
  const World& world_;
  std::vector<Lamp> lamps_;
  double ambient_ = 0;
  std::map<std::string, LedRing> rings_;
  std::map<std::string, Speaker> speakers_;
  double temperature_ = 22.0;
  std::vector<std::pair<double, double>> humidity_log_;
};

}  // namespace sensors
}  // namespace sbot
