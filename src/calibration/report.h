// `sbot_calibrate compare`: replay a dataset with one or more model variants and write a report
// (Markdown + CSV data + PNG plots drawn by plot_report.py with matplotlib).
#pragma once

#include <string>
#include <vector>

#include "calibration/evaluation.h"

namespace sbot::calib {

struct ChannelMetrics {
  std::string run, channel;
  std::size_t n = 0;
  double rmse = 0;       ///< channel units
  double fit = 0;        ///< NRMSE fit [%] = 100 (1 - |y - yhat| / |y - mean(y)|)
  double nrms = 0;       ///< normalised RMS (noise floor ~ 1)
  double ss_residual = 0, ss_measured = 0;  ///< sum (y - yhat)^2, sum (y - mean(y))^2: fits pool over runs
};

struct VariantSummary {
  std::string label;
  ModelSpec model;
  double nrms = 0;                        ///< over every sample
  std::map<std::string, double> group_nrms;   ///< per channel group
  std::map<std::string, double> group_rmse;   ///< per channel group, channel units
  std::vector<ChannelMetrics> channels;   ///< per run and channel
  std::vector<std::string> notes;
  std::vector<ReplaySensitivity> sensitivity;  ///< per drive run (compare only; evaluation.h)
};

struct CompareOptions {
  std::string out_dir;
  bool plots = true;
  double window = 2.0;       ///< [s] time window of the heat map
  EvalOptions eval;
};

/// Replay `variants` (label, model) and write the report into opt.out_dir. Returns the summaries.
std::vector<VariantSummary> writeCompareReport(const Dataset& ds,
                                               const std::vector<std::pair<std::string, ModelSpec>>& variants,
                                               const CompareOptions& opt, WorkerPool& pool);

/// Metrics of one evaluation (used by compare and the sweep).
VariantSummary summarise(const Dataset& ds, const Evaluation& ev, const std::string& label, const ModelSpec& m);

/// Directory of the Python helpers (plot_report.py, bag_to_dataset.py).
std::string scriptDirectory();

}  // namespace sbot::calib
