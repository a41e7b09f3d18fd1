#include "sbot_sim/core/effects/effect_registry.h"

#include <cmath>
#include <mutex>
#include <sstream>

#include "sbot_sim/core/errors.h"

namespace sbot {

const ParamSpec* EffectInfo::findParam(const std::string& n) const {
  for (const auto& p : params)
    if (p.name == n) return &p;
  return nullptr;
}

const ParamSpec* EffectInfo::specFor(const std::string& n) const {
  if (open_params) return params.empty() ? nullptr : &params.front();
  return findParam(n);
}

ParametricEffect::ParametricEffect(EffectInfo info, const std::map<std::string, double>& values)
    : info_(std::move(info)) {
  if (!info_.open_params)
    for (const auto& p : info_.params) values_[p.name] = p.null_value;
  for (const auto& [k, v] : values) values_[k] = v;
}

double ParametricEffect::param(const std::string& n) const {
  auto it = values_.find(n);
  if (it != values_.end()) return it->second;
  const ParamSpec* s = info_.specFor(n);
  if (!s) throw UnknownName("effect " + info_.name + " has no parameter '" + n + "'");
  return s->null_value;
}

double ParametricEffect::paramOr(const std::string& n, double fallback) const {
  auto it = values_.find(n);
  return it == values_.end() ? fallback : it->second;
}

bool ParametricEffect::isNull() const {
  for (const auto& [k, v] : values_) {
    const ParamSpec* s = info_.specFor(k);
    if (s && v != s->null_value) return false;
  }
  return true;
}

EffectRegistry& EffectRegistry::instance() {
  static EffectRegistry registry;
  static std::once_flag once;
  std::call_once(once, [] { registerBuiltinEffects(registry); });
  return registry;
}

void EffectRegistry::add(EffectInfo info, EffectFactory factory) {
  const std::string name = info.name;
  if (index_.count(name)) throw ConfigError("<effect registry>", name, "effect registered twice");
  index_[name] = entries_.size();
  entries_.push_back({std::move(info), std::move(factory)});
}

const EffectInfo& EffectRegistry::info(const std::string& name) const {
  auto it = index_.find(name);
  if (it == index_.end()) throw UnknownName("unknown effect '" + name + "'");
  return entries_[it->second].info;
}

std::size_t EffectRegistry::position(const std::string& name) const {
  auto it = index_.find(name);
  if (it == index_.end()) throw UnknownName("unknown effect '" + name + "'");
  return it->second;
}

std::vector<std::string> EffectRegistry::names() const {
  std::vector<std::string> out;
  for (const auto& e : entries_) out.push_back(e.info.name);
  return out;
}

ParametricEffectPtr EffectRegistry::create(const std::string& name, const std::map<std::string, double>& params,
                                           const std::string& source, const std::string& field) const {
  auto it = index_.find(name);
  if (it == index_.end()) {
    std::ostringstream known;
    for (const auto& e : entries_) known << (e.info.name == entries_.front().info.name ? "" : ", ") << e.info.name;
    throw ConfigError(source, field.empty() ? "name" : field + ".name",
                      "unknown effect '" + name + "' (known: " + known.str() + ")");
  }
  const Entry& e = entries_[it->second];
  const std::string pfield = (field.empty() ? "" : field + ".") + "params";
  for (const auto& [k, v] : params) {
    const ParamSpec* s = e.info.specFor(k);
    if (!s) {
      std::ostringstream known;
      for (const auto& p : e.info.params) known << (&p == &e.info.params.front() ? "" : ", ") << p.name;
      throw ConfigError(source, pfield + "." + k,
                        "effect " + name + " has no parameter '" + k + "' (parameters: " + known.str() + ")");
    }
    if (!std::isfinite(v)) throw ConfigError(source, pfield + "." + k, "must be a finite number");
    if (v < s->lower || v > s->upper) {
      std::ostringstream msg;
      // Dimensionless parameters have unit "1", which read as part of the value ("value -1 1").
      const std::string unit = s->unit == "1" || s->unit.empty() ? "" : " " + s->unit;
      msg << "value " << v << unit << " is outside the physical bounds [" << s->lower << ", " << s->upper << "]" << unit;
      throw ConfigError(source, pfield + "." + k, msg.str());
    }
  }
  return e.factory(params);
}

}  // namespace sbot
