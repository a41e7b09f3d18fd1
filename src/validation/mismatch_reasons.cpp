#include "mismatch_reasons.h"

#include <algorithm>
#include <stdexcept>
#include <utility>

#include <yaml-cpp/yaml.h>

#include "yaml_file.h"

namespace sbot {
namespace validation {

MismatchReasons MismatchReasons::load(const std::string& path, const std::string& shown_as) {
  auto fail = [&](const std::string& why) { throw std::runtime_error("mismatch reasons " + path + ": " + why); };
  const YAML::Node root = loadYamlFile("mismatch reasons", path);
  MismatchReasons r;
  r.source_ = shown_as.empty() ? path : shown_as;
  if (root.IsNull()) return r;  // an empty file: nothing explained
  if (!root.IsMap()) fail("expected a map from cell (\"4.3 10 mm backward\") to reason");
  for (const auto& entry : root) {
    const std::string key = entry.first.as<std::string>("");
    if (key.empty()) fail("an entry has an empty cell name");
    if (!entry.second.IsScalar() || entry.second.as<std::string>("").empty())
      fail("the reason for '" + key + "' is not a text");
    r.reasons_[key] = entry.second.as<std::string>();
  }
  return r;
}

MismatchReasons MismatchReasons::none() {
  return MismatchReasons();  // no source: fromFile() is false
}

std::vector<std::string> MismatchReasons::keys() const {
  std::vector<std::string> k;
  for (const auto& entry : reasons_) k.push_back(entry.first);
  return k;
}

std::string MismatchReasons::record(const std::string& key, bool match) {
  if (match) {
    if (explains(key)) stale_.push_back(key);
    return "match";
  }
  pending_.push_back(key);
  if (!explains(key)) unexplained_.push_back(key);
  return "**mismatch**";
}

std::string MismatchReasons::explainPending() {
  if (pending_.empty()) return "";
  // Cells that share a reason (several gap widths of one level, say) are listed together, once.
  const std::string unexplained = "**not explained yet**: a new mismatch, to be analysed";
  std::vector<std::pair<std::string, std::string>> groups;  // (reason, cells), in the table's order
  for (const std::string& key : pending_) {
    auto it = reasons_.find(key);
    const std::string& reason = it != reasons_.end() ? it->second : unexplained;
    auto g = std::find_if(groups.begin(), groups.end(), [&](const auto& x) { return x.first == reason; });
    if (g == groups.end()) groups.push_back({reason, "*" + key + "*"});
    else g->second += ", *" + key + "*";
  }
  pending_.clear();
  std::string md = fromFile() ? "Why these cells do not match (`" + source_ + "`):\n\n"
                              : "Why these cells do not match (no reasons file; `--reasons FILE` records them):\n\n";
  for (const auto& [reason, cells] : groups) {
    std::string one_line = reason;  // a line break would end the Markdown list item
    std::replace(one_line.begin(), one_line.end(), '\n', ' ');
    md += "- " + cells + ": " + one_line + "\n";
  }
  return md + "\n";
}

}  // namespace validation
}  // namespace sbot
