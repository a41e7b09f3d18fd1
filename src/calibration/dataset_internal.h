// What dataset.cpp (dataset.yaml) shares with dataset_csv.cpp (the run files); not part of the
// calibration's API.
#pragma once

#include <string>

namespace sbot::calib::detail {

/// `v` as std::ostream prints it (the refusals' numbers).
std::string fmtNumber(double v);

/// Why a measured value cannot be a reading of its channel ("" if it can): the sensors' documented
/// ranges (docs/calibration.md), and for the rest bounds no s-bot reaches, so that a unit mistake or
/// a corrupt cell is named instead of dominating every error figure.
std::string channelRangeProblem(const std::string& channel, double v);

}  // namespace sbot::calib::detail
