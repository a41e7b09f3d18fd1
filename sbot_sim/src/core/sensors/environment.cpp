#include "sbot_sim/core/sensors/environment.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "sbot_sim/core/world.h"

namespace sbot::sensors {

double blinkPeriod(unsigned code) {
  static const double periods[] = {0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 1.0, 2.0, 3.0, 4.0, 5.0};
  if (code > BLINKING_RATE_0_2) {
    throw std::out_of_range("unknown blinking rate code " + std::to_string(code) +
                            " (sbot.h BLINKING_RATE_xx: 0..10)");
  }
  return periods[code];
}

std::array<LinkRef, kLedGroups> ledGroupFrames() {
  std::array<LinkRef, kLedGroups> frames;
  for (int g = 0; g < kLedGroups; ++g) frames[g] = LinkRef("light_" + std::to_string(g));
  return frames;
}

bool LedRing::isLit(int group, double time) const {
  if (group < 0 || group >= kLedGroups) throw std::out_of_range("LED group must be in [0,7]");
  const LedGroup& g = groups[group];
  if (!g.on()) return false;
  const double period = blinkPeriod(g.blink);
  if (period <= 0) return true;
  // Phase in [0, period); a tiny epsilon keeps t = since + k*period/2 on the intended side
  // despite floating-point accumulation of the step time.
  double phase = std::fmod(time - g.since + 1e-9, period);
  if (phase < 0) phase += period;
  return phase < 0.5 * period;
}

bool LedRing::anyOn() const {
  for (const auto& g : groups)
    if (g.on()) return true;
  return false;
}

Environment::Environment(const World& world) : world_(world) {
  humidity_log_.emplace_back(-std::numeric_limits<double>::infinity(), 45.0);
}

double Environment::time() const { return world_.time(); }

int Environment::addLamp(const Vec3& position, double intensity_mcd, const Vec3& colour) {
  if (!(intensity_mcd >= 0) || !std::isfinite(intensity_mcd)) {
    throw std::invalid_argument("lamp intensity must be a finite value >= 0 [mcd]");
  }
  // The light sensors cast occlusion rays towards each lamp; ODE cannot index rays that long.
  const std::string where = positionProblem(position);
  if (!where.empty()) throw std::invalid_argument("lamp: " + where);
  lamps_.push_back(Lamp{position, intensity_mcd, colour});
  return static_cast<int>(lamps_.size()) - 1;
}

void Environment::setLampIntensity(int nr, double intensity_mcd) {
  if (nr < 0 || nr >= static_cast<int>(lamps_.size())) throw std::out_of_range("no lamp " + std::to_string(nr));
  if (!(intensity_mcd >= 0) || !std::isfinite(intensity_mcd)) {
    throw std::invalid_argument("lamp intensity must be a finite value >= 0 [mcd]");
  }
  lamps_[nr].intensity = intensity_mcd;
}

double Environment::getLampIntensity(int nr) const {
  if (nr < 0 || nr >= static_cast<int>(lamps_.size())) throw std::out_of_range("no lamp " + std::to_string(nr));
  return lamps_[nr].intensity;
}

void Environment::setLampPosition(int nr, const Vec3& position) {
  if (nr < 0 || nr >= static_cast<int>(lamps_.size())) throw std::out_of_range("no lamp " + std::to_string(nr));
  const std::string where = positionProblem(position);
  if (!where.empty()) throw std::invalid_argument("lamp " + std::to_string(nr) + ": " + where);
  lamps_[nr].position = position;
}

void Environment::setAmbientLight(double v) {
  if (!(v >= 0) || !std::isfinite(v)) throw std::invalid_argument("ambient light must be >= 0 [mcd/cm^2]");
  ambient_ = v;
}

LedRing& Environment::ring(const std::string& robot) { return rings_[robot]; }

void Environment::setLightColor(const std::string& robot, int group, unsigned r, unsigned g, unsigned b,
                                unsigned blink) {
  if (group < 0 || group >= kLedGroups) throw std::out_of_range("LED group must be in [0,7]");
  blinkPeriod(blink);  // validates the code
  LedGroup& led = ring(robot).groups[group];
  led.r = std::min(r, kLedMaxUnits);
  led.g = std::min(g, kLedMaxUnits);
  led.b = std::min(b, kLedMaxUnits);
  led.blink = blink;
  led.since = time();
}

void Environment::setAllLightColor(const std::string& robot, const std::array<unsigned, kLedGroups>& r,
                                   const std::array<unsigned, kLedGroups>& g,
                                   const std::array<unsigned, kLedGroups>& b,
                                   const std::array<unsigned, kLedGroups>& blink) {
  for (unsigned code : blink) blinkPeriod(code);  // validate all before changing any
  for (int i = 0; i < kLedGroups; ++i) setLightColor(robot, i, r[i], g[i], b[i], blink[i]);
}

void Environment::setSameLightColor(const std::string& robot, unsigned r, unsigned g, unsigned b,
                                    unsigned blink) {
  blinkPeriod(blink);
  for (int i = 0; i < kLedGroups; ++i) setLightColor(robot, i, r, g, b, blink);
}

const LedRing& Environment::ledRing(const std::string& robot) const {
  static const LedRing dark;
  auto it = rings_.find(robot);
  return it == rings_.end() ? dark : it->second;
}

bool Environment::isLit(const std::string& robot, int group, double time) const {
  return ledRing(robot).isLit(group, time);
}

void Environment::setSpeaker(const std::string& robot, double frequency_hz, double intensity) {
  if (!(frequency_hz > 0) || !std::isfinite(frequency_hz)) throw std::invalid_argument("speaker frequency must be > 0 [Hz]");
  if (!(intensity >= 0) || !std::isfinite(intensity)) throw std::invalid_argument("speaker intensity must be >= 0");
  speakers_[robot] = Speaker{true, frequency_hz, intensity};
}

void Environment::stopSpeaker(const std::string& robot) {
  auto it = speakers_.find(robot);
  if (it != speakers_.end()) it->second.on = false;
}

const Speaker& Environment::speaker(const std::string& robot) const {
  static const Speaker silent;
  auto it = speakers_.find(robot);
  return it == speakers_.end() ? silent : it->second;
}

void Environment::forgetRobot(const std::string& robot) {
  rings_.erase(robot);
  speakers_.erase(robot);
}

void Environment::setHumidity(double percent) {
  if (!std::isfinite(percent)) throw std::invalid_argument("humidity must be finite [%]");
  const double v = std::max(0.0, std::min(100.0, percent));
  const double t = time();
  // Several changes at the same instant: the last one wins.
  if (humidity_log_.size() > 1 && humidity_log_.back().first >= t) {
    humidity_log_.back().second = v;
  } else {
    humidity_log_.emplace_back(t, v);
  }
}

}  // namespace sbot::sensors
