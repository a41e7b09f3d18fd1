#include "calibration/report.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <set>
#include <iomanip>
#include <sstream>

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>  // environ

#include <cerrno>
#include <cstdio>
#include <cstring>

#include "sbot_sim/core/output_files.h"

namespace sbot::calib {
namespace {

/// NRMSE fit [%] = 100 (1 - |y - yhat| / |y - mean(y)|) from the two sums of squares; NaN for a flat y.
double nrmseFit(double ss_residual, double ss_measured) {
  return ss_measured > 0 ? 100 * (1 - std::sqrt(ss_residual / ss_measured)) : std::numeric_limits<double>::quiet_NaN();
}

std::string f(double v, int prec = 4) {
  if (!std::isfinite(v)) return "n/a";
  std::ostringstream o;
  o << std::setprecision(prec) << v;
  return o.str();
}

std::string fixed(double v, int digits) {
  if (!std::isfinite(v)) return "n/a";
  std::ostringstream o;
  o << std::fixed << std::setprecision(digits) << v;
  return o.str();
}

std::string jsonEscape(const std::string& s) {
  std::string o;
  for (char c : s) {
    if (c == '"' || c == '\\') o += '\\';
    if (c == '\n') {
      o += "\\n";
      continue;
    }
    o += c;
  }
  return o;
}

std::string unitOf(const std::string& c) {
  const std::string g = NoiseModel::group(c);
  if (g == "position") return "m";
  if (g == "yaw" || g == "tilt") return "rad";
  return "units";
}

/// Runs `program` with `args` (no shell: the arguments reach it as they are, whatever characters
/// a path holds) and waits. Returns "" on success, else what went wrong.
std::string runScript(const std::string& program, const std::vector<std::string>& args) {
  std::vector<char*> argv;
  argv.push_back(const_cast<char*>(program.c_str()));
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  pid_t pid = 0;
  if (const int rc = posix_spawn(&pid, program.c_str(), nullptr, nullptr, argv.data(), environ); rc != 0)
    return "cannot start " + program + ": " + std::strerror(rc);
  int status = 0;
  if (waitpid(pid, &status, 0) < 0) return "waiting for " + program + ": " + std::strerror(errno);
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return "";
  std::string cmd = program;
  for (const auto& a : args) cmd += " '" + a + "'";
  return cmd + (WIFEXITED(status) ? " exited with status " + std::to_string(WEXITSTATUS(status)) : " was killed");
}

}  // namespace

std::string scriptDirectory() {
  if (const char* e = std::getenv("SBOT_CALIBRATION_SCRIPTS")) return e;
#ifdef SBOT_CALIBRATION_SCRIPT_DIR
  return SBOT_CALIBRATION_SCRIPT_DIR;
#else
  return "src/calibration";
#endif
}

VariantSummary summarise(const Dataset& ds, const Evaluation& ev, const std::string& label, const ModelSpec& m) {
  VariantSummary s;
  s.label = label;
  s.model = m;
  double tot = 0;
  std::size_t totn = 0;
  std::map<std::string, std::pair<double, std::size_t>> gn, gr;
  for (const auto& rr : ev.runs) {
    const Run& run = ds.runs[rr.run];
    for (const auto& note : rr.prediction.notes)
      if (std::find(s.notes.begin(), s.notes.end(), note) == s.notes.end()) s.notes.push_back(note);
    for (std::size_t ci = 0; ci < rr.channels.size(); ++ci) {
      const std::string& c = rr.channels[ci];
      ChannelMetrics cm;
      cm.run = run.name;
      cm.channel = c;
      double ss_raw = 0, ss_r = 0;
      std::vector<double> y;
      for (std::size_t i = 0; i < rr.r.size(); ++i) {
        if (rr.chan[i] != static_cast<int>(ci) || !rr.valid[i]) continue;
        ss_raw += rr.raw[i] * rr.raw[i];
        ss_r += huberLoss(rr.r[i], 3.0);
        ++cm.n;
      }
      const Series& ser = run.channels.at(c);
      double mean = 0;
      for (double v : ser.v) mean += v;
      mean /= std::max<std::size_t>(1, ser.v.size());
      double ss_y = 0;
      std::size_t k = 0;
      for (std::size_t i = 0; i < rr.r.size(); ++i) {
        if (rr.chan[i] != static_cast<int>(ci)) continue;
        const std::size_t idx = k++;
        if (!rr.valid[i]) continue;
        double d = ser.v[idx] - mean;
        if (c == "yaw") d = wrapAngle(d);
        ss_y += d * d;
      }
      if (cm.n == 0) {
        cm.rmse = cm.fit = cm.nrms = std::numeric_limits<double>::quiet_NaN();
      } else {
        cm.rmse = std::sqrt(ss_raw / cm.n);
        cm.nrms = std::sqrt(ss_r / cm.n);
        cm.ss_residual = ss_raw;
        cm.ss_measured = ss_y;
        cm.fit = nrmseFit(ss_raw, ss_y);
        const std::string g = NoiseModel::group(c);
        gn[g].first += ss_r;
        gn[g].second += cm.n;
        gr[g].first += ss_raw;
        gr[g].second += cm.n;
        tot += ss_r;
        totn += cm.n;
      }
      s.channels.push_back(cm);
    }
  }
  s.nrms = totn ? std::sqrt(tot / totn) : std::numeric_limits<double>::quiet_NaN();
  for (const auto& [g, v] : gn) s.group_nrms[g] = std::sqrt(v.first / std::max<std::size_t>(1, v.second));
  for (const auto& [g, v] : gr) s.group_rmse[g] = std::sqrt(v.first / std::max<std::size_t>(1, v.second));
  return s;
}

namespace {

/// data/v<i>/<run>.csv (every sample of every channel with its features) and <run>_trace.csv (the
/// simulated trajectory, every third step) of one variant's replay of one run, for the plots.
void writeRunData(const Dataset& ds, const RunResiduals& rr, const std::string& vdir) {
  const Run& run = ds.runs[rr.run];
  OutputFile o(vdir + "/" + run.name + ".csv");
  o << "channel,t,measured,predicted,residual,normalised,valid,v,w,accel,contact,yaw,distance,incidence,surface\n";
  o << std::setprecision(9);
  for (std::size_t ci = 0; ci < rr.channels.size(); ++ci) {
    const std::string& c = rr.channels[ci];
    const Series& ser = run.channels.at(c);
    const auto& pred = rr.prediction.values.at(c);
    const auto fit = rr.prediction.features.find(c);
    const auto sit = rr.prediction.surface.find(c);
    std::size_t k = 0;
    for (std::size_t i = 0; i < rr.r.size(); ++i) {
      if (rr.chan[i] != static_cast<int>(ci)) continue;
      const std::size_t idx = k++;
      auto feat = [&](const char* name) {
        if (fit == rr.prediction.features.end()) return std::string();
        auto it = fit->second.find(name);
        if (it == fit->second.end() || idx >= it->second.size() || !std::isfinite(it->second[idx])) return std::string();
        std::ostringstream s;
        s << std::setprecision(7) << it->second[idx];
        return s.str();
      };
      o << c << "," << ser.t[idx] << "," << ser.v[idx] << "," << (std::isfinite(pred[idx]) ? f(pred[idx], 9) : "")
        << "," << (rr.valid[i] ? f(rr.raw[i], 9) : "") << "," << (rr.valid[i] ? f(rr.r[i], 7) : "") << ","
        << static_cast<int>(rr.valid[i]) << "," << feat("v") << "," << feat("w") << "," << feat("accel") << ","
        << feat("contact") << "," << feat("yaw") << "," << feat("distance") << "," << feat("incidence") << ","
        << (sit != rr.prediction.surface.end() && idx < sit->second.size() ? sit->second[idx] : "") << "\n";
    }
  }
  o.commit();
  const Trace& tr = rr.prediction.trace;
  if (!tr.t.empty()) {
    OutputFile t(vdir + "/" + run.name + "_trace.csv");
    t << "t,x,y,yaw,v,w,cmd_left,cmd_right,speed_left,speed_right,contact\n" << std::setprecision(8);
    for (std::size_t i = 0; i < tr.t.size(); i += 3)
      t << tr.t[i] << "," << tr.x[i] << "," << tr.y[i] << "," << tr.yaw[i] << "," << tr.v[i] << "," << tr.w[i]
        << "," << tr.cmd_left[i] << "," << tr.cmd_right[i] << ","
        << (i < tr.speed_left.size() ? tr.speed_left[i] : 0) << ","
        << (i < tr.speed_right.size() ? tr.speed_right[i] : 0) << "," << static_cast<int>(tr.contact[i]) << "\n";
    t.commit();
  }
}

/// summary.json for plot_report.py.
void writeSummaryJson(const Dataset& ds, const std::vector<VariantSummary>& sums, const CompareOptions& opt) {
  OutputFile j(opt.out_dir + "/summary.json");
  j << std::setprecision(9) << "{\n  \"dataset\": \"" << jsonEscape(ds.name) << "\",\n  \"window\": " << opt.window
    << ",\n  \"runs\": [";
  for (std::size_t i = 0; i < ds.runs.size(); ++i)
    j << (i ? ", " : "") << "{\"name\": \"" << jsonEscape(ds.runs[i].name) << "\", \"kind\": \""
      << (ds.runs[i].kind == RunKind::Drive ? "drive" : "place") << "\", \"t_end\": " << ds.runs[i].t_end << "}";
  j << "],\n  \"variants\": [\n";
  for (std::size_t vi = 0; vi < sums.size(); ++vi) {
    const auto& s = sums[vi];
    j << "    {\"label\": \"" << jsonEscape(s.label) << "\", \"model\": \"" << jsonEscape(s.model.describe())
      << "\", \"dir\": \"data/v" << vi << "\", \"nrms\": " << (std::isfinite(s.nrms) ? s.nrms : -1)
      << ", \"group_nrms\": {";
    bool first = true;
    for (const auto& [g, v] : s.group_nrms) {
      j << (first ? "" : ", ") << "\"" << g << "\": " << v;
      first = false;
    }
    j << "}}" << (vi + 1 < sums.size() ? "," : "") << "\n";
  }
  j << "  ]\n}\n";
  j.commit();
}

/// The report's title, dataset, units and notes, and the summary table.
void writeSummary(OutputFile& md, const Dataset& ds, const std::vector<std::pair<std::string, ModelSpec>>& variants,
                  const std::vector<VariantSummary>& sums, bool drawn) {
  md << "# Model vs measurements: " << ds.name << "\n\n";
  md << "Dataset `" << ds.yaml_path << "` (" << ds.runs.size() << " runs, " << ds.sampleCount()
     << " measured samples), model level **" << (variants.empty() ? ds.robot : variants.front().second.level)
     << "**.\n\n";
  md << "Errors are measured minus simulated. *RMSE* is in the channel's unit; *fit* is the NRMSE fit "
        "100 (1 - |y - y_sim| / |y - mean(y)|) in %; *nRMS* is the RMS of the residual divided by the "
        "channel's noise scale (dataset `noise:`), so the noise floor is ~1.";
  if (ds.align_initial_pose)
    md << " Drive runs: the simulated planar pose is re-anchored to the tracker every " << ds.align_segment
       << " s (a rigid correction per segment; the first one within the start pose's tracker noise).";
  md << "\n\n";
  for (const auto& s : sums)
    for (const auto& n : s.notes) md << "> note (" << s.label << "): " << n << "\n\n";

  md << "## Summary\n\n| model | effects | nRMS (all) |";
  std::set<std::string> groups;
  for (const auto& s : sums)
    for (const auto& [g, v] : s.group_nrms) groups.insert(g);
  for (const auto& g : groups) md << " " << g << " RMSE | " << g << " nRMS |";
  md << "\n|---|---|---|";
  for (std::size_t i = 0; i < groups.size(); ++i) md << "---|---|";
  md << "\n";
  for (const auto& s : sums) {
    md << "| " << s.label << " | " << s.model.describe() << " | " << f(s.nrms) << " |";
    for (const auto& g : groups) {
      auto a = s.group_rmse.find(g), b = s.group_nrms.find(g);
      md << " " << (a != s.group_rmse.end() ? f(a->second) : "-") << " | "
         << (b != s.group_nrms.end() ? f(b->second) : "-") << " |";
    }
    md << "\n";
  }
  md << "\n";
  if (sums.size() > 1 && drawn) {
    md << "### Before / after\n\n![before and after](plots/before_after.png)\n\n"
       << "### Waterfall (effects added one by one)\n\n![waterfall](plots/waterfall.png)\n\n";
  }
}

/// Which residuals can be read as missing physics at all (evaluation.h, ReplaySensitivity).
void writeReproducibility(OutputFile& md, const Dataset& ds, const std::vector<VariantSummary>& sums) {
  bool any_drive = false;
  for (const auto& s : sums) any_drive |= !s.sensitivity.empty();
  if (any_drive) {
    md << "## Reproducibility of the replays\n\n"
       << "Each drive run was replayed twice more, from starts moved by +" << kStartNudge << " and -" << kStartNudge
       << " sigma of the tracker's noise (x, y, yaw). A run whose prediction then moves by more than " << kChaoticSensitivity
       << " of the noise (nRMS) is chaotic in that model: its residual shows where the simulated trajectory "
          "happened to go, not which physics is missing, and no effect can fit it. `diagnose` and `fit` leave such "
          "runs out (unless --keep-chaotic); drive them more gently to test them, and read their plots, not their "
          "numbers.\n\n";
    for (const auto& s : sums) {
      if (s.sensitivity.empty()) continue;
      const std::string chaotic = describeChaoticRuns(ds, s.sensitivity);
      const auto most = std::max_element(s.sensitivity.begin(), s.sensitivity.end(),
                                         [](const auto& a, const auto& b) { return a.nrms < b.nrms; });
      if (chaotic.empty())
        md << "- " << s.label << ": every drive run is reproducible (largest " << f(most->nrms, 2) << ", "
           << ds.runs[most->run].name << ").\n";
      else
        md << "- " << s.label << ": **not reproducible**: " << chaotic << " (nRMS, and the channel that moved most).\n";
    }
    md << "\n";
  }
}

void writePerRunChannel(OutputFile& md, const std::vector<VariantSummary>& sums) {
  md << "## Per run and channel\n\n";
  md << "| run | channel | unit | n |";
  for (const auto& s : sums) md << " RMSE " << s.label << " | fit % " << s.label << " | nRMS " << s.label << " |";
  md << "\n|---|---|---|---|";
  for (std::size_t i = 0; i < sums.size(); ++i) md << "---|---|---|";
  md << "\n";
  if (!sums.empty()) {
    for (std::size_t k = 0; k < sums.front().channels.size(); ++k) {
      const auto& c0 = sums.front().channels[k];
      md << "| " << c0.run << " | " << c0.channel << " | " << unitOf(c0.channel) << " | " << c0.n << " |";
      for (const auto& s : sums) {
        const auto& c = s.channels[k];
        md << " " << f(c.rmse) << " | " << fixed(c.fit, 1) << " | " << f(c.nrms, 3) << " |";
      }
      md << "\n";
    }
  }
  md << "\n";
}

/// Per sensor (ir/ground/light) over all runs; whether the dataset has such sensors.
bool writePerSensor(OutputFile& md, const std::vector<VariantSummary>& sums) {
  bool sensors = false;
  for (const auto& s : sums)
    for (const auto& c : s.channels) {
      const std::string g = NoiseModel::group(c.channel);
      sensors |= g == "ir" || g == "ground" || g == "light";
    }
  if (sensors && !sums.empty()) {
    md << "## Per sensor (all runs)\n\n| sensor |";
    for (const auto& s : sums) md << " RMSE " << s.label << " | fit % " << s.label << " | nRMS " << s.label << " |";
    md << "\n|---|";
    for (std::size_t i = 0; i < sums.size(); ++i) md << "---|---|---|";
    md << "\n";
    std::set<std::string> chans;
    for (const auto& c : sums.front().channels) {
      const std::string g = NoiseModel::group(c.channel);
      if (g == "ir" || g == "ground" || g == "light") chans.insert(c.channel);
    }
    for (const auto& ch : chans) {
      md << "| " << ch << " |";
      for (const auto& s : sums) {
        double a = 0, b = 0, ss_res = 0, ss_meas = 0;
        std::size_t n = 0;
        for (const auto& c : s.channels)
          if (c.channel == ch && c.n) {
            a += c.rmse * c.rmse * c.n;
            b += c.nrms * c.nrms * c.n;
            ss_res += c.ss_residual;
            ss_meas += c.ss_measured;  // about each run's mean: the variation within runs explained
            n += c.n;
          }
        md << " " << (n ? f(std::sqrt(a / n)) : "n/a") << " | " << (n ? fixed(nrmseFit(ss_res, ss_meas), 1) : "n/a")
           << " | " << (n ? f(std::sqrt(b / n), 3) : "n/a") << " |";
      }
      md << "\n";
    }
    md << "\n";
  }
  return sensors;
}

/// The plots of the failures (or why there are none).
void writePlotSection(OutputFile& md, const CompareOptions& opt, bool sensors, bool drawn,
                      const std::string& plot_problem) {
  std::vector<std::pair<std::string, std::string>> plots = {
      {"Error by run and time window", "heatmap.png"},
      {"Trajectories (measured vs simulated, open loop from the start pose)", "trajectories.png"},
      {"Residual against time (turns shaded, contacts marked)", "residual_time.png"},
      {"Residual against inputs and features", "residual_features.png"},
      {"Parity (measured against simulated)", "parity.png"}};
  if (sensors) plots.push_back({"Sensors: residual against distance, incidence angle and surface", "sensor_features.png"});
  md << "## Where the model fails\n\n";
  if (!opt.plots) md << "Plots not drawn (`--no-plots`): `plot_report.py " << opt.out_dir << "` draws them.\n\n";
  else if (!drawn) md << "> plots could not be drawn: " << plot_problem << "\n\n";
  else
    for (const auto& [title, file] : plots) md << "### " << title << "\n\n![" << title << "](plots/" << file << ")\n\n";
}

/// The plots, drawn by plot_report.py from summary.json and the CSV files. A reused output folder
/// must not show an earlier dataset's plots. "" when drawn (or not asked for), else the problem.
std::string drawPlots(const CompareOptions& opt) {
  for (const char* png : {"heatmap.png", "trajectories.png", "residual_time.png", "residual_features.png", "parity.png",
                          "sensor_features.png", "before_after.png", "waterfall.png"})
    std::remove((opt.out_dir + "/plots/" + png).c_str());
  return opt.plots ? runScript("/usr/bin/python3", {scriptDirectory() + "/plot_report.py", opt.out_dir}) : "";
}

}  // namespace

std::vector<VariantSummary> writeCompareReport(const Dataset& ds,
                                               const std::vector<std::pair<std::string, ModelSpec>>& variants,
                                               const CompareOptions& opt, WorkerPool& pool) {
  makeOutputDirectory(opt.out_dir + "/data");
  makeOutputDirectory(opt.out_dir + "/plots");
  EvalOptions eo = opt.eval;
  eo.replay.keep_trace = true;
  std::vector<VariantSummary> sums;
  for (std::size_t vi = 0; vi < variants.size(); ++vi) {
    Evaluation ev = evaluate(ds, variants[vi].second, allRuns(ds), eo, pool);
    sums.push_back(summarise(ds, ev, variants[vi].first, variants[vi].second));
    sums.back().sensitivity = replaySensitivity(ds, variants[vi].second, opt.eval, pool);
    // Per-sample data and traces for the plots.
    const std::string vdir = opt.out_dir + "/data/v" + std::to_string(vi);
    makeOutputDirectory(vdir);
    for (const auto& rr : ev.runs) writeRunData(ds, rr, vdir);
  }
  writeSummaryJson(ds, sums, opt);
  const std::string plot_problem = drawPlots(opt);
  const bool drawn = opt.plots && plot_problem.empty();

  // The Markdown report.
  OutputFile md(opt.out_dir + "/report.md");
  writeSummary(md, ds, variants, sums, drawn);
  writeReproducibility(md, ds, sums);
  writePerRunChannel(md, sums);
  const bool sensors = writePerSensor(md, sums);
  writePlotSection(md, opt, sensors, drawn, plot_problem);
  md.commit();
  if (!plot_problem.empty())
    std::fprintf(stderr, "sbot_calibrate: warning: plots could not be drawn: %s\n", plot_problem.c_str());
  return sums;
}

}  // namespace sbot::calib
