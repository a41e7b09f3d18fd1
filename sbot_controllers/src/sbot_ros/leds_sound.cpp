// sbot.h LED ring (set_leds) and speaker (playMusic: one tone per file name).
#include "api.h"

#include <sbot_msgs/SetLeds.h>
#include <std_msgs/Float64.h>

namespace {

using namespace sbot_api;

void leds(const std::vector<unsigned>& groups, const unsigned* r, const unsigned* gr, const unsigned* b,
          const BlinkingRate* blink, bool same, const char* fn) {
  sbot_msgs::SetLeds srv;
  for (std::size_t i = 0; i < groups.size(); ++i) {
    const std::size_t k = same ? 0 : i;
    if (groups[i] > 7) {  // named with the caller's value (the uint8 field made 300 read "group 255")
      report(false, "%s: light group %u outside [0, 7]", fn, groups[i]);
      return;
    }
    srv.request.group.push_back(static_cast<uint8_t>(groups[i]));
    srv.request.r.push_back(static_cast<uint8_t>(r[k] > 255 ? 255 : r[k]));
    srv.request.g.push_back(static_cast<uint8_t>(gr[k] > 255 ? 255 : gr[k]));
    srv.request.b.push_back(static_cast<uint8_t>(b[k] > 255 ? 255 : b[k]));
    srv.request.blink.push_back(static_cast<uint8_t>(blink[k] > 255 ? 255 : blink[k]));
  }
  call("set_leds", srv, fn);
}

}  // namespace

using namespace sbot_api;

extern "C" {

void setLightColor(unsigned light, unsigned r, unsigned gr, unsigned b, BlinkingRate blink) {
  leds({light}, &r, &gr, &b, &blink, true, "setLightColor");
}

void setAllLightColor(unsigned r[8], unsigned gr[8], unsigned b[8], BlinkingRate blink[8]) {
  leds({0, 1, 2, 3, 4, 5, 6, 7}, r, gr, b, blink, false, "setAllLightColor");
}

void setSameLightColor(unsigned r, unsigned gr, unsigned b, BlinkingRate blink) {
  leds({0, 1, 2, 3, 4, 5, 6, 7}, &r, &gr, &b, &blink, true, "setSameLightColor");
}

void playMusic(const char* filename) {
  if (!ready("playMusic")) return;
  std::uint32_t h = 2166136261u;  // FNV-1a
  for (const char* p = filename ? filename : ""; *p; ++p) h = (h ^ static_cast<unsigned char>(*p)) * 16777619u;
  std_msgs::Float64 m;
  m.data = 200.0 + static_cast<double>(h % 1800u);
  g->speaker_pub.publish(m);
  ++g->speaker_sent;
}

void stopMusic(void) {
  if (!ready("stopMusic")) return;
  std_msgs::Float64 m;
  m.data = 0;
  g->speaker_pub.publish(m);
  ++g->speaker_sent;
}

}  // extern "C"
