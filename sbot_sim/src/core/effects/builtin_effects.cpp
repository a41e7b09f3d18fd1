// THE list of built-in effects: one line per effect. Order = the order the workbench tries them.
#include "sbot_sim/core/effects/drive_effects.h"
#include "sbot_sim/core/effects/effect_registry.h"
#include "sbot_sim/core/effects/sensor_effects.h"

namespace sbot {

void registerBuiltinEffects(EffectRegistry& r) {
  // drive: command path
  r.add<SpeedScaleEffect>();
  r.add<MotorAsymmetryEffect>();
  r.add<TrackWidthEffect>();
  r.add<TurnSkidEffect>();
  r.add<LatencyEffect>();
  r.add<DeadBandEffect>();
  r.add<MotorLagEffect>();
  r.add<AccelLimitEffect>();
  r.add<TorqueSaturationEffect>();
  r.add<BatterySagEffect>();
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
