#include "sensor_publisher.h"

namespace sbot_node {

#define SBOT_SENSOR_PUBLISHER(name) const SensorPublisherType& name##Publisher();
#include "table.h"
#undef SBOT_SENSOR_PUBLISHER

const std::vector<const SensorPublisherType*>& sensorPublisherTable() {
  static const std::vector<const SensorPublisherType*> table = {
#define SBOT_SENSOR_PUBLISHER(name) &name##Publisher(),
#include "table.h"
#undef SBOT_SENSOR_PUBLISHER
  };
  return table;
}

bool RobotTopics::due(const std::string& channel, double t) {
  Rate& r = rates_[channel];
  if (t + 1e-9 < r.next) return false;
  const double period = 1.0 / r.hz;
  r.next += period;
  if (r.next <= t) r.next = t + period;  // fell behind (rate raised, reset): restart the phase
  return subs_[channel].any();
}

bool RobotTopics::dueWithSingles(const std::string& channel, const std::string& single_prefix, int count,
                                 double t, bool& any_single) {
  const bool was_due = t + 1e-9 >= rates_[channel].next;
  any_single = false;
  if (was_due)
    for (int k = 0; k < count; ++k) any_single = any_single || subs_[single_prefix + std::to_string(k)].any();
  return due(channel, t) || (was_due && any_single);
}

}  // namespace sbot_node
