#include "picker_localisation/sensors_ranging/range_histogram_filter.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>

namespace picker_localisation {
namespace sensors {

void normaliseGrid(std::vector<float>& grid, float threshold, float p_min) {
  float max = 0.0f;
  for (float v : grid) max = std::max(max, v);
  if (!(max > 0.0f)) {
    std::fill(grid.begin(), grid.end(), p_min);
    return;
  }
  const float inv = 1.0f / max;
  for (float& v : grid) {
    const float n = v * inv;
    v = n > threshold ? std::max(n, p_min) : p_min;
  }
}

RangeHistogramFilter::RangeHistogramFilter(RhfOptions options) : options_(options) {
  if (!(options_.resolution > 0.0) || !(options_.size_x >= options_.resolution) ||
      !(options_.size_y >= options_.resolution))
    throw std::invalid_argument("RangeHistogramFilter: sizes and resolution must be > 0 (size >= resolution)");
  for (double p : {options_.p_min_uwb, options_.p_min_cam, options_.p_min_obs, options_.p_min_inov})
    if (!(p > 0.0 && p <= 1.0)) throw std::invalid_argument("RangeHistogramFilter: P_min floors must be in (0, 1]");
  if (!(options_.p_threshold >= 0.0 && options_.p_threshold < 1.0))
    throw std::invalid_argument("RangeHistogramFilter: p_threshold must be in [0, 1)");
  if (!(options_.max_speed >= 0.0)) throw std::invalid_argument("RangeHistogramFilter: max_speed must be >= 0");
  nx_ = static_cast<int>(std::lround(options_.size_x / options_.resolution));
  ny_ = static_cast<int>(std::lround(options_.size_y / options_.resolution));
  const std::size_t n = static_cast<std::size_t>(nx_) * ny_;
  m_.assign(n, 1.0f);
  tmp_.assign(n, 0.0f);
  uwb_.assign(n, 1.0f);
  cam_.assign(n, static_cast<float>(options_.p_min_cam));
  mark_.assign(n, 0);
  min_x_ = -0.5 * nx_ * options_.resolution;
  min_y_ = -0.5 * ny_ * options_.resolution;
}

void RangeHistogramFilter::reset() {
  std::fill(m_.begin(), m_.end(), 1.0f);
  initialised_ = false;
}

Eigen::Vector2d RangeHistogramFilter::cellCentre(int ix, int iy) const {
  return {min_x_ + (ix + 0.5) * options_.resolution, min_y_ + (iy + 0.5) * options_.resolution};
}

void RangeHistogramFilter::touch(std::size_t i) {
  if (!mark_[i]) {
    mark_[i] = 1;
    touched_.push_back(static_cast<std::uint32_t>(i));
  }
}

// UWB grid (Eq. 5) as factors over the floor product P_min^uwb^(anchors), on the annuli only. Returns the
// largest factor (>= 1).
float RangeHistogramFilter::rangeGrid(const std::vector<RangeMeasurement>& ranges, const Eigen::Isometry2d& pose) {
  const float pmin = static_cast<float>(options_.p_min_uwb);
  const float cut = std::max(static_cast<float>(options_.p_threshold), pmin);  // p <= cut: Eq. 3 gives P_min
  const double res = options_.resolution;
  const double ln_cut = -std::log(static_cast<double>(cut));
  for (const RangeMeasurement& m : ranges) {
    const double sigma = m.variance > 0.0 ? std::sqrt(m.variance) : options_.default_range_sigma;
    const double b = std::max(sigma, 1e-3) / std::sqrt(2.0);
    const double band = b * ln_cut;
    const Eigen::Vector2d a = pose * m.anchor;
    const double r_out = m.range + band, r_in = m.range - band;
    const float inv_b = static_cast<float>(1.0 / b);
    const float inv_pmin = 1.0f / pmin;
    const int iy0 = std::max(0, static_cast<int>(std::floor((a.y() - r_out - min_y_) / res)));
    const int iy1 = std::min(ny_ - 1, static_cast<int>(std::ceil((a.y() + r_out - min_y_) / res)));
    for (int iy = iy0; iy <= iy1; ++iy) {
      const double dy = min_y_ + (iy + 0.5) * res - a.y();
      const double dy2 = dy * dy;
      if (dy2 > r_out * r_out) continue;
      const double half_out = std::sqrt(r_out * r_out - dy2);
      const double half_in = (r_in > 0.0 && dy2 < r_in * r_in) ? std::sqrt(r_in * r_in - dy2) : -1.0;
      // x intervals: [a.x - half_out, a.x - half_in] and [a.x + half_in, a.x + half_out] (one when no hole).
      const double lo[2] = {a.x() - half_out, half_in < 0.0 ? 1e300 : a.x() + half_in};
      const double hi[2] = {half_in < 0.0 ? a.x() + half_out : a.x() - half_in, a.x() + half_out};
      const std::size_t row = static_cast<std::size_t>(iy) * nx_;
      const float fdy2 = static_cast<float>(dy2);
      const float fr = static_cast<float>(m.range);
      int next_free = 0;  // the two intervals may reach the same cell near the hole: visit each cell once
      for (int k = 0; k < 2; ++k) {
        if (lo[k] > hi[k]) continue;
        const int ix0 = std::max(next_free, static_cast<int>(std::floor((lo[k] - min_x_) / res - 0.5)));
        const int ix1 = std::min(nx_ - 1, static_cast<int>(std::ceil((hi[k] - min_x_) / res - 0.5)));
        if (ix1 >= ix0) next_free = ix1 + 1;
        float dx = static_cast<float>(min_x_ + (ix0 + 0.5) * res - a.x());
        const float step = static_cast<float>(res);
        for (int ix = ix0; ix <= ix1; ++ix, dx += step) {
          const float d = std::sqrt(dx * dx + fdy2);
          const float p = std::exp(-std::abs(fr - d) * inv_b);
          if (p > cut) {  // Eq. 3 per anchor: f = p (> P_min); the factor over the floor is p / P_min
            touch(row + ix);
            uwb_[row + ix] *= p * inv_pmin;
          }
        }
      }
    }
  }
  float fmax = 1.0f;
  for (std::uint32_t i : touched_) fmax = std::max(fmax, uwb_[i]);
  return fmax;
}

namespace {
// Solution set of a * x + c > 0 intersected into [lo, hi].
void clipHalfLine(double a, double c, double& lo, double& hi) {
  if (a > 0.0) lo = std::max(lo, -c / a);
  else if (a < 0.0) hi = std::min(hi, -c / a);
  else if (!(c > 0.0)) hi = -1e300;
}
}  // namespace

// Camera grid (Eq. 6) into cam_ (touched cells), for the bearings that pass the camera gate against the UWB
// grid (normalised by inv_fmax). Returns the number of bearings used.
std::size_t RangeHistogramFilter::bearingGrid(const std::vector<BearingMeasurement>& bearings,
                                              const Eigen::Isometry2d& pose, float inv_fmax) {
  const double cut = std::max(options_.p_threshold, options_.p_min_cam);
  const float thr = static_cast<float>(options_.p_threshold), pu = static_cast<float>(options_.p_min_uwb);
  const float gate = static_cast<float>(options_.camera_gate);
  const double yaw = std::atan2(pose.linear()(1, 0), pose.linear()(0, 0));
  const double res = options_.resolution;
  std::size_t used = 0;
  for (const BearingMeasurement& bm : bearings) {
    if (!std::isfinite(bm.bearing) || !bm.origin.allFinite() || !std::isfinite(bm.sigma)) continue;
    const double sigma = bm.sigma > 0.0 ? bm.sigma : options_.default_bearing_sigma;
    // Half opening of the wedge where exp(-0.5 (da / sigma)^2) > cut.
    const double lim = std::min(sigma * std::sqrt(2.0 * std::log(1.0 / cut)), 0.5 * M_PI - 1e-3);
    const double t = std::tan(lim);
    const Eigen::Vector2d o = pose * bm.origin;
    const double th = bm.bearing + yaw;
    const double ux = std::cos(th), uy = std::sin(th);
    const float k = static_cast<float>(-0.5 / (sigma * sigma));
    const float fux = static_cast<float>(ux), fuy = static_cast<float>(uy), ft = static_cast<float>(t);
    wedge_.clear();
    float score = 0.0f;
    for (int iy = 0; iy < ny_; ++iy) {
      const double vy = min_y_ + (iy + 0.5) * res - o.y();
      // along > 0, t * along - lat > 0, t * along + lat > 0: three half-lines in vx.
      double lo = -1e300, hi = 1e300;
      clipHalfLine(ux, uy * vy, lo, hi);
      clipHalfLine(t * ux + uy, vy * (t * uy - ux), lo, hi);
      clipHalfLine(t * ux - uy, vy * (t * uy + ux), lo, hi);
      if (lo > hi) continue;
      const int ix0 = std::max(0, static_cast<int>(std::floor((lo + o.x() - min_x_) / res - 0.5)));
      const int ix1 = std::min(nx_ - 1, static_cast<int>(std::ceil((hi + o.x() - min_x_) / res - 0.5)));
      const std::size_t row = static_cast<std::size_t>(iy) * nx_;
      const float fvy = static_cast<float>(vy);
      for (int ix = ix0; ix <= ix1; ++ix) {
        const float vx = static_cast<float>(min_x_ + (ix + 0.5) * res - o.x());
        const float along = fux * vx + fuy * fvy;
        const float lat = fux * fvy - fuy * vx;
        if (along <= 0.0f || std::abs(lat) >= along * ft) continue;
        const float diff = std::atan(lat / along);
        const float p = std::exp(k * diff * diff);
        if (!(p > cut)) continue;
        wedge_.push_back({static_cast<std::uint32_t>(row + ix), p});
        const float u = uwb_[row + ix] * inv_fmax;
        score = std::max(score, p * ((u > thr && u > pu) ? u : pu));
      }
    }
    if (gate > 0.0f && score < gate) continue;  // no target-like UWB cell on this wedge
    ++used;
    for (const auto& [i, p] : wedge_)
      if (p > cam_[i]) {
        touch(i);
        cam_[i] = p;
      }
  }
  return used;
}

// tmp_ = M_{t-1} shifted by (sx, sy) cells (re-centring; cells from outside = 0), dilated along x by k cells.
void RangeHistogramFilter::dilateRows(int sx, int sy, int k) {
  const int n = nx_ + 2 * k;
  std::vector<float>& b = buf_h_;
  b.assign(n, 0.0f);
  buf_g_.resize(n);
  const int w = 2 * k + 1;
  for (int iy = 0; iy < ny_; ++iy) {
    float* out = &tmp_[static_cast<std::size_t>(iy) * nx_];
    const int oy = iy + sy;
    if (oy < 0 || oy >= ny_) {
      std::fill(out, out + nx_, 0.0f);
      continue;
    }
    const float* src = &m_[static_cast<std::size_t>(oy) * nx_];
    // b[j] = src[j - k + sx] where that is inside the row.
    std::fill(b.begin(), b.end(), 0.0f);
    const int j0 = std::max(0, k - sx), j1 = std::min(n, nx_ + k - sx);
    if (j1 > j0) std::memcpy(&b[j0], src + (j0 - k + sx), sizeof(float) * (j1 - j0));
    if (k == 0) {
      std::memcpy(out, b.data(), sizeof(float) * nx_);
    } else if (k <= 6) {
      std::memcpy(out, b.data(), sizeof(float) * nx_);
      for (int s = 1; s < w; ++s) {
        const float* bs = b.data() + s;
        for (int i = 0; i < nx_; ++i) out[i] = std::max(out[i], bs[i]);
      }
    } else {  // van Herk / Gil-Werman
      std::vector<float> h(n);
      for (int s = 0; s < n; s += w) {
        const int e = std::min(s + w, n);
        buf_g_[s] = b[s];
        for (int j = s + 1; j < e; ++j) buf_g_[j] = std::max(buf_g_[j - 1], b[j]);
        h[e - 1] = b[e - 1];
        for (int j = e - 2; j >= s; --j) h[j] = std::max(h[j + 1], b[j]);
      }
      for (int i = 0; i < nx_; ++i) out[i] = std::max(h[i], buf_g_[i + w - 1]);
    }
  }
}

// m_ = scale * Eq.3_inov(dilate_y(tmp_, k)) (or scale everywhere when !dilate_source). Returns via m_.
void RangeHistogramFilter::dilateColumnsTimes(int k, float scale, bool dilate_source) {
  const std::size_t nx = static_cast<std::size_t>(nx_);
  if (!dilate_source) {
    std::fill(m_.begin(), m_.end(), scale);
    return;
  }
  const float thr = static_cast<float>(options_.p_threshold), pmin = static_cast<float>(options_.p_min_inov);
  const float cut = std::max(thr, pmin);
  std::vector<float> acc(nx);
  auto emit = [&](int iy, const float* v) {
    float* out = &m_[iy * nx];
    for (std::size_t i = 0; i < nx; ++i) out[i] = scale * (v[i] > cut ? v[i] : pmin);
  };
  if (k <= 6) {
    for (int iy = 0; iy < ny_; ++iy) {
      const int a = std::max(0, iy - k), e = std::min(ny_ - 1, iy + k);
      std::memcpy(acc.data(), &tmp_[a * nx], sizeof(float) * nx);
      for (int j = a + 1; j <= e; ++j) {
        const float* r = &tmp_[j * nx];
        for (std::size_t i = 0; i < nx; ++i) acc[i] = std::max(acc[i], r[i]);
      }
      emit(iy, acc.data());
    }
    return;
  }
  // van Herk / Gil-Werman on whole rows (padded with zero rows).
  const int w = 2 * k + 1, n = ny_ + 2 * k;
  buf_g_.resize(static_cast<std::size_t>(n) * nx);
  buf_h_.resize(static_cast<std::size_t>(n) * nx);
  auto src = [&](int j) -> const float* {
    const int iy = j - k;
    return (iy >= 0 && iy < ny_) ? &tmp_[iy * nx] : nullptr;
  };
  auto load = [&](float* dst, const float* b) {
    if (b) std::memcpy(dst, b, sizeof(float) * nx);
    else std::fill(dst, dst + nx, 0.0f);
  };
  for (int s = 0; s < n; s += w) {
    const int e = std::min(s + w, n);
    load(&buf_g_[s * nx], src(s));
    for (int j = s + 1; j < e; ++j) {
      float* gj = &buf_g_[j * nx];
      const float* gp = gj - nx;
      const float* b = src(j);
      if (b) for (std::size_t i = 0; i < nx; ++i) gj[i] = std::max(gp[i], b[i]);
      else std::memcpy(gj, gp, sizeof(float) * nx);
    }
    load(&buf_h_[(e - 1) * nx], src(e - 1));
    for (int j = e - 2; j >= s; --j) {
      float* hj = &buf_h_[j * nx];
      const float* hn = hj + nx;
      const float* b = src(j);
      if (b) for (std::size_t i = 0; i < nx; ++i) hj[i] = std::max(hn[i], b[i]);
      else std::memcpy(hj, hn, sizeof(float) * nx);
    }
  }
  for (int iy = 0; iy < ny_; ++iy) {
    const float* h = &buf_h_[iy * nx];
    const float* g = &buf_g_[(iy + w - 1) * nx];
    for (std::size_t i = 0; i < nx; ++i) acc[i] = std::max(h[i], g[i]);
    emit(iy, acc.data());
  }
}

std::optional<RhfEstimate> RangeHistogramFilter::update(double stamp, const std::vector<RangeMeasurement>& ranges,
                                                        const std::vector<BearingMeasurement>& bearings,
                                                        const Eigen::Isometry2d& robot_pose) {
  if (!std::isfinite(stamp) || (initialised_ && stamp < last_stamp_)) return std::nullopt;
  std::vector<RangeMeasurement> valid;
  valid.reserve(ranges.size());
  for (const RangeMeasurement& r : ranges)
    if (std::isfinite(r.range) && r.range >= 0.0 && r.anchor.allFinite() && std::isfinite(r.variance))
      valid.push_back(r);
  if (valid.empty() || !robot_pose.matrix().allFinite()) return std::nullopt;

  // Re-centre the grid on the robot by whole cells.
  const double res = options_.resolution;
  const Eigen::Vector2d centre(min_x_ + 0.5 * nx_ * res, min_y_ + 0.5 * ny_ * res);
  const Eigen::Vector2d robot = robot_pose.translation();
  const double fx = std::round((robot.x() - centre.x()) / res), fy = std::round((robot.y() - centre.y()) / res);
  const bool far = std::abs(fx) >= nx_ || std::abs(fy) >= ny_;  // nothing of the old grid survives
  const int sx = far ? 0 : static_cast<int>(fx), sy = far ? 0 : static_cast<int>(fy);
  min_x_ += fx * res;
  min_y_ += fy * res;

  // Observation (Eqs. 3-6), sparse: values at untouched cells are the constants below.
  const float thr = static_cast<float>(options_.p_threshold);
  const float pu = static_cast<float>(options_.p_min_uwb), pc = static_cast<float>(options_.p_min_cam),
              po = static_cast<float>(options_.p_min_obs);
  auto eq3 = [thr](float v, float pmin) { return (v > thr && v > pmin) ? v : pmin; };
  const float fmax = rangeGrid(valid, robot_pose);
  const float inv_fmax = 1.0f / fmax;
  const std::size_t bearings_used = bearingGrid(bearings, robot_pose, inv_fmax);
  const bool has_cam = bearings_used > 0;
  auto uwb_at = [&](std::size_t i) { return eq3(uwb_[i] * inv_fmax, pu); };
  auto cam_at = [&](std::size_t i) { return has_cam ? cam_[i] : 1.0f; };
  const float raw0 = eq3(inv_fmax, pu) * (has_cam ? pc : 1.0f);
  float omax = raw0;
  for (std::uint32_t i : touched_) omax = std::max(omax, uwb_at(i) * cam_at(i));
  const float inv_omax = 1.0f / omax;
  const float c_out = eq3(raw0 * inv_omax, po);  // M^O at every untouched cell (its minimum)

  // Innovation (Eq. 7) fused with Eq. 2: m_ = c_out * M^I, then the touched cells get M^O(i) * M^I(i).
  if (initialised_ && !far) {
    const double dt = std::max(stamp - last_stamp_, 0.0);
    const int k = std::min(std::max(nx_, ny_),
                           static_cast<int>(std::ceil(options_.max_speed * dt / res - 1e-9)));
    dilateRows(sx, sy, k);
    dilateColumnsTimes(k, c_out, true);
  } else {
    dilateColumnsTimes(0, c_out, false);  // first update (or a jump beyond the grid): M^I = 1
  }
  const float inv_c_out = 1.0f / c_out;
  for (std::uint32_t i : touched_) {
    const float o = eq3(uwb_at(i) * cam_at(i) * inv_omax, po);
    m_[i] = o * (m_[i] * inv_c_out);
  }
  for (std::uint32_t i : touched_) {
    uwb_[i] = 1.0f;
    cam_[i] = pc;
    mark_[i] = 0;
  }
  touched_.clear();
  initialised_ = true;
  last_stamp_ = stamp;
  RhfEstimate e = normaliseAndEstimate();
  e.bearings_used = bearings_used;
  return e;
}

// M_t /= max (Eq. 2 normalisation) and the estimate, in one pass after finding the max.
RhfEstimate RangeHistogramFilter::normaliseAndEstimate() {
  float max = 0.0f;
  for (float v : m_) max = std::max(max, v);
  const float inv = max > 0.0f ? 1.0f / max : 1.0f;
  const double res = options_.resolution;
  const float thr = static_cast<float>(options_.output_threshold);
  double w = 0.0, sx = 0.0, sy = 0.0, sxx = 0.0, sxy = 0.0, syy = 0.0;
  std::size_t count = 0;
  bool border = false;
  for (int iy = 0; iy < ny_; ++iy) {
    float* row = &m_[static_cast<std::size_t>(iy) * nx_];
    const double y = (iy + 0.5) * res;  // relative to min (better conditioned sums)
    for (int ix = 0; ix < nx_; ++ix) {
      const float v = row[ix] * inv;
      row[ix] = v;
      if (v <= thr) continue;
      if (ix == 0 || iy == 0 || ix == nx_ - 1 || iy == ny_ - 1) border = true;
      const double x = (ix + 0.5) * res;
      w += v;
      sx += v * x;
      sy += v * y;
      sxx += v * x * x;
      sxy += v * x * y;
      syy += v * y * y;
      ++count;
    }
  }
  RhfEstimate e;
  e.support_cells = count;
  e.touches_border = border;
  if (!(w > 0.0)) {  // only when output_threshold >= 1
    e.position = Eigen::Vector2d(min_x_ + 0.5 * nx_ * res, min_y_ + 0.5 * ny_ * res);
    e.covariance = Eigen::Matrix2d::Identity() * (options_.size_x * options_.size_x / 12.0);
    return e;
  }
  const double mx = sx / w, my = sy / w;
  e.position = Eigen::Vector2d(min_x_ + mx, min_y_ + my);
  e.covariance << sxx / w - mx * mx, sxy / w - mx * my, sxy / w - mx * my, syy / w - my * my;
  e.covariance += Eigen::Matrix2d::Identity() * (res * res / 12.0);
  return e;
}

}  // namespace sensors
}  // namespace picker_localisation
