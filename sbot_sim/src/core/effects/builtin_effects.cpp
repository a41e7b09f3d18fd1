// THE list of built-in effects: one line per effect. The order is the pipeline order: a world
// applies its effects in this order whatever order an effects file lists them in (makeEffects), so
// an effects file is a set and a fitted file means the same as the hidden one it was fitted to. The
// command path follows the signal: the radio link, the motor controller, the motor and its supply,
// the drive train, then the ground.
#include "sbot_sim/core/effects/drive_effects.h"
#include "sbot_sim/core/effects/effect_registry.h"
#include "sbot_sim/core/effects/sensor_effects.h"

namespace sbot {

void registerBuiltinEffects(EffectRegistry& r) {
  // drive: command path
  r.add<LatencyEffect>();
  r.add<DeadBandEffect>();
  r.add<AccelLimitEffect>();
  r.add<MotorLagEffect>();
  r.add<BatterySagEffect>();
  r.add<MotorAsymmetryEffect>();
  r.add<SpeedScaleEffect>();
  r.add<TorqueSaturationEffect>();
  r.add<TrackWidthEffect>();
  r.add<TurnSkidEffect>();
  // drive: contact path
  r.add<RollingResistanceEffect>();
  r.add<TrackFrictionAnisotropyEffect>();
  // sensors
  r.add<IrReflectanceEffect>();
  r.add<IrIncidenceEffect>();
  r.add<IrAmbientEffect>();
  r.add<IrGainOffsetEffect>();
  r.add<LightAngularEffect>();
  r.add<LightAmbientEffect>();
}

}  // namespace sbot
