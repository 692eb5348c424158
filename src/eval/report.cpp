#include "picker_localisation/eval/report.h"

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <stdexcept>

namespace picker_localisation {
namespace eval {

const char* const kSummaryCsvHeader =
    "method,runs,euclidean_mean,euclidean_std,topological_mean,topological_std,right_lane_share,right_lane_share_std";

namespace {

std::ofstream openOut(const std::string& path) {
  std::ofstream f(path);
  if (!f) throw std::runtime_error("cannot write '" + path + "'");
  f << std::setprecision(6);
  return f;
}

std::string num(double v, int precision = 4) {
  if (std::isnan(v)) return "nan";
  std::ostringstream s;
  s << std::fixed << std::setprecision(precision) << v;
  return s.str();
}

}  // namespace

void writeRunCsv(const std::string& path, const topology::TopologicalMap& map,
                 const std::vector<ErrorSample>& samples) {
  std::ofstream f = openOut(path);
  f << "stamp,picker_id,estimated_node,true_node,true_x,true_y,euclidean,topological,lane_applicable,"
       "in_true_lane\n";
  for (const auto& s : samples) {
    f << num(s.stamp, 3) << ',' << s.picker_id << ',' << map.node(s.estimated_node).name << ','
      << map.node(s.true_node).name << ',' << num(s.true_position.x(), 3) << ','
      << num(s.true_position.y(), 3) << ',' << num(s.euclidean, 4) << ',' << s.topological << ','
      << int(s.lane_applicable) << ',' << int(s.in_true_lane) << '\n';
  }
  if (!f) throw std::runtime_error("error writing '" + path + "'");
}

std::string summaryCsv(const std::vector<MethodSummary>& rows) {
  std::ostringstream f;
  f << kSummaryCsvHeader << '\n';
  for (const auto& r : rows) {
    if (!r.available) {
      f << r.method << ",0,unavailable,unavailable,unavailable,unavailable,unavailable,unavailable\n";
      continue;
    }
    f << r.method << ',' << r.runs << ',' << num(r.euclidean_mean) << ',' << num(r.euclidean_std) << ','
      << num(r.topological_mean) << ',' << num(r.topological_std) << ',' << num(r.right_lane_share) << ','
      << num(r.right_lane_share_std) << '\n';
  }
  return f.str();
}

void writeSummaryCsv(const std::string& path, const std::vector<MethodSummary>& rows) {
  std::ofstream f = openOut(path);
  f << summaryCsv(rows);
  if (!f) throw std::runtime_error("error writing '" + path + "'");
}

std::string summaryMarkdown(const std::string& title, const std::vector<MethodSummary>& rows) {
  std::ostringstream f;
  f << "### " << title << "\n\n";
  f << "| method | runs | Euclidean error [m] mean (std over runs) | pooled std [m] | topological error "
       "[nodes] mean (std over runs) | pooled std [nodes] | right-lane share mean (std over runs) |\n";
  f << "|---|---|---|---|---|---|---|\n";
  for (const auto& r : rows) {
    if (!r.available) {
      f << "| " << r.method << " | - | unavailable: " << r.unavailable_reason << " | | | | |\n";
      continue;
    }
    f << "| " << r.method << " | " << r.runs << " | " << num(r.euclidean_mean, 2) << " ("
      << num(r.euclidean_std, 2) << ") | " << num(r.euclidean_pooled_std, 2) << " | "
      << num(r.topological_mean, 2) << " (" << num(r.topological_std, 2) << ") | "
      << num(r.topological_pooled_std, 2) << " | " << num(r.right_lane_share, 3) << " ("
      << num(r.right_lane_share_std, 3) << ") |\n";
  }
  return f.str();
}

void writeSummaryMarkdown(const std::string& path, const std::string& title,
                          const std::vector<MethodSummary>& rows) {
  std::ofstream f = openOut(path);
  f << summaryMarkdown(title, rows);
  if (!f) throw std::runtime_error("error writing '" + path + "'");
}

std::string errorTable(const std::vector<std::pair<std::string, std::vector<ErrorSample>>>& per_picker) {
  std::ostringstream f;
  auto row = [&](const std::string& name, const std::vector<ErrorSample>& samples) {
    const RunMetrics r = summariseRun(samples);
    f << std::left << std::setw(14) << name << std::right << std::setw(8) << r.samples << std::setw(10)
      << num(r.euclidean_mean, 2) << std::setw(9) << num(r.euclidean_std, 2) << std::setw(10)
      << num(r.topological_mean, 2) << std::setw(9) << num(r.topological_std, 2) << std::setw(11)
      << num(r.right_lane_share, 3) << '\n';
  };
  f << std::left << std::setw(14) << "picker" << std::right << std::setw(8) << "samples" << std::setw(10)
    << "eucl[m]" << std::setw(9) << "std" << std::setw(10) << "topo[n]" << std::setw(9) << "std"
    << std::setw(11) << "right_lane" << '\n';
  std::vector<ErrorSample> all;
  for (const auto& [id, samples] : per_picker) {
    row(id, samples);
    all.insert(all.end(), samples.begin(), samples.end());
  }
  row("all", all);
  return f.str();
}

ErrorSeries binErrors(const std::string& method, const std::vector<std::vector<ErrorSample>>& runs, double t0,
                      double bin_width) {
  ErrorSeries s;
  s.method = method;
  if (!(bin_width > 0.0)) throw std::invalid_argument("binErrors: bin width must be > 0");
  std::vector<double> eu_sum, topo_sum;
  std::vector<std::size_t> eu_n, topo_n;
  for (const auto& run : runs) {
    for (const auto& e : run) {
      const double rel = e.stamp - t0;
      if (rel < 0.0) continue;
      const std::size_t b = static_cast<std::size_t>(rel / bin_width);
      if (b >= eu_sum.size()) {
        eu_sum.resize(b + 1, 0.0);
        topo_sum.resize(b + 1, 0.0);
        eu_n.resize(b + 1, 0);
        topo_n.resize(b + 1, 0);
      }
      eu_sum[b] += e.euclidean;
      ++eu_n[b];
      if (e.topological >= 0) {
        topo_sum[b] += e.topological;
        ++topo_n[b];
      }
    }
  }
  for (std::size_t b = 0; b < eu_sum.size(); ++b) {
    if (eu_n[b] == 0) continue;
    s.t.push_back((static_cast<double>(b) + 0.5) * bin_width);
    s.euclidean.push_back(eu_sum[b] / static_cast<double>(eu_n[b]));
    s.topological.push_back(topo_n[b] ? topo_sum[b] / static_cast<double>(topo_n[b]) : 0.0);
  }
  return s;
}

namespace {

cv::Scalar colourOf(std::size_t i) {
  static const cv::Scalar palette[] = {{180, 119, 31},  {14, 127, 255}, {44, 160, 44},   {40, 39, 214},
                                       {189, 103, 148}, {75, 86, 140},  {194, 119, 227}, {127, 127, 127},
                                       {34, 189, 188},  {207, 190, 23}};
  return palette[i % (sizeof(palette) / sizeof(palette[0]))];
}

void drawPanel(cv::Mat& img, const cv::Rect& area, const std::vector<ErrorSeries>& series, bool topological,
               const std::string& ylabel) {
  double t_max = 1.0, y_max = 1e-9;
  for (const auto& s : series) {
    for (std::size_t i = 0; i < s.t.size(); ++i) {
      t_max = std::max(t_max, s.t[i]);
      y_max = std::max(y_max, topological ? s.topological[i] : s.euclidean[i]);
    }
  }
  y_max *= 1.1;
  cv::rectangle(img, area, cv::Scalar(0, 0, 0), 1);
  const auto px = [&](double t, double y) {
    return cv::Point(area.x + static_cast<int>(t / t_max * area.width),
                     area.y + area.height - static_cast<int>(y / y_max * area.height));
  };
  for (int k = 0; k <= 4; ++k) {  // y ticks
    const double y = y_max * k / 4.0;
    const cv::Point p = px(0.0, y);
    cv::line(img, p, cv::Point(area.x + area.width, p.y), cv::Scalar(225, 225, 225), 1);
    std::ostringstream l;
    l << std::fixed << std::setprecision(1) << y;
    cv::putText(img, l.str(), cv::Point(area.x - 45, p.y + 4), cv::FONT_HERSHEY_SIMPLEX, 0.4,
                cv::Scalar(0, 0, 0));
  }
  // t ticks at a round step (1, 2 or 5 x 10^k s), about five of them
  const double raw_step = t_max / 5.0;
  const double decade = std::pow(10.0, std::floor(std::log10(raw_step)));
  const double step =
      raw_step / decade < 2.0 ? 2.0 * decade : (raw_step / decade < 5.0 ? 5.0 * decade : 10.0 * decade);
  for (double t = 0.0; t <= t_max + 1e-9; t += step) {
    const cv::Point p = px(t, 0.0);
    std::ostringstream l;
    l << std::fixed << std::setprecision(0) << t;
    cv::putText(img, l.str(), cv::Point(p.x - 10, p.y + 16), cv::FONT_HERSHEY_SIMPLEX, 0.4,
                cv::Scalar(0, 0, 0));
  }
  cv::putText(img, ylabel, cv::Point(area.x + 5, area.y - 6), cv::FONT_HERSHEY_SIMPLEX, 0.5,
              cv::Scalar(0, 0, 0));
  for (std::size_t k = 0; k < series.size(); ++k) {
    const auto& s = series[k];
    for (std::size_t i = 1; i < s.t.size(); ++i) {
      const double y0 = topological ? s.topological[i - 1] : s.euclidean[i - 1];
      const double y1 = topological ? s.topological[i] : s.euclidean[i];
      cv::line(img, px(s.t[i - 1], y0), px(s.t[i], y1), colourOf(k), 2, cv::LINE_AA);
    }
  }
}

}  // namespace

void plotErrors(const std::string& path, const std::vector<ErrorSeries>& series, int width, int height) {
  cv::Mat img(height, width, CV_8UC3, cv::Scalar(255, 255, 255));
  const int left = 60, right = 200, top = 30, gap = 50, bottom = 40;
  const int panel_h = (height - top - gap - bottom) / 2;
  const cv::Rect upper(left, top, width - left - right, panel_h);
  const cv::Rect lower(left, top + panel_h + gap, width - left - right, panel_h);
  drawPanel(img, upper, series, false, "Euclidean error [m]");
  drawPanel(img, lower, series, true, "topological error [nodes]");
  cv::putText(img, "simulated time [s]", cv::Point(left + upper.width / 2 - 60, height - 8),
              cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(0, 0, 0));
  for (std::size_t k = 0; k < series.size(); ++k) {  // legend
    const int y = top + 10 + static_cast<int>(k) * 20;
    cv::line(img, cv::Point(width - right + 15, y), cv::Point(width - right + 40, y), colourOf(k), 3);
    cv::putText(img, series[k].method, cv::Point(width - right + 45, y + 4), cv::FONT_HERSHEY_SIMPLEX, 0.45,
                cv::Scalar(0, 0, 0));
  }
  if (!cv::imwrite(path, img)) throw std::runtime_error("cannot write image '" + path + "'");
}

}  // namespace eval
}  // namespace picker_localisation
