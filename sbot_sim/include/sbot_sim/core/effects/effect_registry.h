// The effects library: parametric physical effects that plug into the core through effects.h, and
// the registry that names them. Every effect declares its parameters (name, unit, null value that
// switches the effect off, physical bounds, typical scale); the calibration workbench fits those
// parameters by re-simulation and the simulator loads them from effects files (effects_file.h).
//
// Adding an effect = one class deriving from ParametricEffect with a static `describe()` plus one
// line in src/core/effects/builtin_effects.cpp (see docs/calibration.md, "Adding an effect").
#pragma once

#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "sbot_sim/core/effects.h"

namespace sbot {

/// One parameter of an effect.
struct ParamSpec {
  std::string name;
  std::string unit;          ///< "1" for dimensionless
  double null_value = 0;     ///< the value at which the effect does nothing
  double lower = -std::numeric_limits<double>::infinity();  ///< physical bounds (inclusive)
  double upper = std::numeric_limits<double>::infinity();
  double scale = 1;          ///< typical magnitude of a departure from null (fit step, damping)
  std::string description;
  /// The local gradient at the start misleads the fitter: a saturation that binds on one side of
  /// null only (torque_saturation below 1), or a cost that jitters at small scales on the six-wheel
  /// model (rolling_resistance). The fitter coarse-scans the range and refines before descending.
  bool scan_first = false;
};

/// Static description of an effect kind.
struct EffectInfo {
  std::string name;          ///< registry key, snake_case, e.g. "speed_scale"
  std::string title;         ///< one line for humans
  std::string path;          ///< "command", "contact" or "sensor"
  std::string description;   ///< the physics, one paragraph
  /// Data channels that can reveal the effect: "pose" (x, y, yaw), "speed", "torque", "tilt",
  /// "ir", "ground", "light". The workbench only tries an effect when its channels are measured.
  std::vector<std::string> channels;
  std::string excited_by;    ///< the experiment that shows it best
  std::vector<ParamSpec> params;
  /// When true the effect also accepts parameters not listed in `params`, each following the spec
  /// `params[0]` (e.g. one reflectance per surface label). `params[0].name` is then a placeholder.
  bool open_params = false;

  const ParamSpec* findParam(const std::string& name) const;
  /// The spec a parameter called `name` obeys (the template for open parameters), or null.
  const ParamSpec* specFor(const std::string& name) const;
};

/// Base class of the library's effects: holds the parameter values; subclasses read them with
/// param(). Per-robot state (buffers, filters) lives in the subclass, keyed by robot name.
class ParametricEffect : public Effect {
 public:
  ParametricEffect(EffectInfo info, const std::map<std::string, double>& values);
  std::string name() const override { return info_.name; }
  const EffectInfo& info() const { return info_; }
  double param(const std::string& name) const;
  /// Parameter value, or `fallback` when the effect was created without it (open parameters).
  double paramOr(const std::string& name, double fallback) const;
  const std::map<std::string, double>& params() const { return values_; }
  /// True when every parameter sits at its null value.
  bool isNull() const;

 private:
  EffectInfo info_;
  std::map<std::string, double> values_;
};

using ParametricEffectPtr = std::shared_ptr<ParametricEffect>;
using EffectFactory = std::function<ParametricEffectPtr(const std::map<std::string, double>&)>;

/// Name -> factory + parameter specs. `instance()` holds every built-in effect.
class EffectRegistry {
 public:
  static EffectRegistry& instance();

  /// Register a class E with `static EffectInfo describe()` and a constructor taking the values.
  template <class E>
  void add() {
    add(E::describe(), [](const std::map<std::string, double>& v) { return std::make_shared<E>(v); });
  }
  void add(EffectInfo info, EffectFactory factory);

  bool has(const std::string& name) const { return index_.count(name) != 0; }
  const EffectInfo& info(const std::string& name) const;  ///< throws UnknownName
  std::vector<std::string> names() const;                   ///< registration order
  /// Place of an effect in the pipeline (registration order); throws UnknownName.
  std::size_t position(const std::string& name) const;

  /// Make an effect. Missing parameters take their null value. Throws ConfigError naming `source`
  /// and `field` (e.g. "effects[2]") for an unknown effect or parameter, a non-finite value or a
  /// value outside the physical bounds.
  ParametricEffectPtr create(const std::string& name, const std::map<std::string, double>& params,
                             const std::string& source = "<effects>", const std::string& field = "") const;

 private:
  struct Entry {
    EffectInfo info;
    EffectFactory factory;
  };
  std::vector<Entry> entries_;
  std::map<std::string, std::size_t> index_;
};

/// Registers the built-in effects (the one list to extend when adding an effect).
void registerBuiltinEffects(EffectRegistry& registry);

/// Per-robot state of an effect, keyed by robot name (effects are shared by all robots of a world).
template <class State>
class PerRobot {
 public:
  State& operator()(const std::string& robot) { return states_[robot]; }
  void clear() { states_.clear(); }
  bool has(const std::string& robot) const { return states_.count(robot) != 0; }

 private:
  std::map<std::string, State> states_;
};

/// Sensor channel name under which Robot::encoderSpeed (getSpeed, the node, the calibration replay)
/// passes the wheel-encoder track speeds [m/s] through Effect::onSensor (index 0 = left, 1 = right).
/// Slip effects use it so that the encoders read wheel rotation, not ground speed.
inline const char* const kTrackSpeedChannel = "track_speed";

}  // namespace sbot
