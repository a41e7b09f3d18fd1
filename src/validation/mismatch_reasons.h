// Why a cell of the validation report does not match the seed.
//
// The analysis of a mismatch (a model limit, a seed inconsistency, what was tried) is written once,
// in config/validation/mismatch_reasons.yaml, keyed by the cell as the report names it
// ("4.3 10 mm backward", "4.5 4.0 cm simple"). sbot_validate prints the reason under the table of
// every cell that mismatches, flags a mismatch nobody has explained yet as new, and lists the
// entries whose cell now matches as stale: the explanation cannot silently drift from the numbers.
#pragma once

#include <map>
#include <string>
#include <vector>

namespace sbot {
namespace validation {

/// The reasons file, relative to the root package (the swarmbot3d source directory).
constexpr const char* kMismatchReasonsFile = "config/validation/mismatch_reasons.yaml";

class MismatchReasons {
 public:
  MismatchReasons() = default;
  /// Reads a YAML map from cell key to reason (a string). Throws std::runtime_error naming the file
  /// and the problem: unreadable, not YAML, not a map, an empty key or a reason that is not a string.
  /// `shown_as`: how the report names the file (default: `path`).
  static MismatchReasons load(const std::string& path, const std::string& shown_as = "");
  /// No reasons (a tables file of your own without a reasons file).
  static MismatchReasons none();

  /// The cells the file gives reasons for.
  std::vector<std::string> keys() const;

  /// Whether the file records a reason for cell `key`.
  bool explains(const std::string& key) const { return reasons_.count(key) != 0; }

  /// Records the outcome of cell `key`; returns the report's match column ("match" / "**mismatch**").
  std::string record(const std::string& key, bool match);

  /// Markdown for the mismatches recorded since the last call (one table's): each cell with its
  /// recorded reason, or marked as not yet explained. Empty when every cell matched.
  std::string explainPending();

  /// Mismatching cells without a recorded reason, and recorded reasons whose cell matched.
  const std::vector<std::string>& unexplained() const { return unexplained_; }
  const std::vector<std::string>& stale() const { return stale_; }

  /// The reasons file as the report names it; empty for none().
  std::string source() const { return source_; }
  bool fromFile() const { return !source_.empty(); }

 private:
  std::string source_;
  std::map<std::string, std::string> reasons_;
  std::vector<std::string> pending_, unexplained_, stale_;
};

}  // namespace validation
}  // namespace sbot
