#include "plslam/eval/chart.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

namespace plslam::eval {
namespace {

constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
constexpr double kTickScale = 0.45;
constexpr double kLabelScale = 0.55;
constexpr double kTitleScale = 0.6;
const cv::Scalar kBlack(0, 0, 0);
const cv::Scalar kGrid(225, 225, 225);
const cv::Scalar kWhite(255, 255, 255);

double nice_step(double range, int target) {
  const double raw = range / std::max(target, 1);
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  const double norm = raw / mag;
  const double nice = norm < 1.5 ? 1.0 : norm < 3.0 ? 2.0 : norm < 7.0 ? 5.0 : 10.0;
  return nice * mag;
}

std::string tick_label(double v, double step) {
  const int decimals = std::max(0, static_cast<int>(-std::floor(std::log10(step) + 1e-9)));
  if (std::abs(v) < step * 1e-6) v = 0.0;  // no "-0.00"
  return fmt::format("{:.{}f}", v, decimals);
}

void put_text(cv::Mat& img, const std::string& text, cv::Point org, double scale, int thickness = 1,
              cv::Scalar color = kBlack) {
  cv::putText(img, text, org, kFont, scale, color, thickness, cv::LINE_AA);
}

cv::Size text_size(const std::string& text, double scale, int thickness = 1) {
  int baseline = 0;
  return cv::getTextSize(text, kFont, scale, thickness, &baseline);
}

// Vertical text, reading bottom to top, centred on `centre`.
void put_vertical_text(cv::Mat& img, const std::string& text, cv::Point centre, double scale) {
  const cv::Size ts = text_size(text, scale);
  cv::Mat patch(ts.height + 8, ts.width + 4, img.type(), kWhite);
  put_text(patch, text, {2, ts.height + 2}, scale);
  cv::Mat rotated;
  cv::rotate(patch, rotated, cv::ROTATE_90_COUNTERCLOCKWISE);
  cv::Rect roi(centre.x - rotated.cols / 2, centre.y - rotated.rows / 2, rotated.cols, rotated.rows);
  roi &= cv::Rect(0, 0, img.cols, img.rows);
  rotated(cv::Rect(0, 0, roi.width, roi.height)).copyTo(img(roi));
}

void dashed_line(cv::Mat& img, cv::Point2d a, cv::Point2d b, const LineStyle& s) {
  if (!s.dashed) {
    cv::line(img, a, b, s.color, s.thickness, cv::LINE_AA);
    return;
  }
  const double len = cv::norm(b - a);
  const double dash = 10.0, gap = 6.0;
  for (double d = 0.0; d < len; d += dash + gap) {
    const cv::Point2d p = a + (b - a) * (d / len);
    const cv::Point2d q = a + (b - a) * (std::min(d + dash, len) / len);
    cv::line(img, p, q, s.color, s.thickness, cv::LINE_AA);
  }
}

}  // namespace

std::vector<double> nice_ticks(double lo, double hi, int target) {
  std::vector<double> ticks;
  if (!(hi > lo)) return ticks;
  const double step = nice_step(hi - lo, target);
  for (double v = std::ceil(lo / step - 1e-9) * step; v <= hi + step * 1e-9; v += step) {
    ticks.push_back(v);
  }
  return ticks;
}

void Chart::add_line(std::vector<cv::Point2d> points, LineStyle style, std::string label) {
  lines_.push_back({std::move(points), style, std::move(label)});
}
void Chart::add_hline(double y, LineStyle style, std::string label) {
  hlines_.push_back({y, style, std::move(label)});
}
void Chart::add_marker(cv::Point2d p, cv::Scalar color, std::string label) {
  markers_.push_back({p, color, std::move(label)});
}

void Chart::draw(cv::Mat& canvas) const {
  canvas.setTo(kWhite);
  // Data bounds.
  double x0 = std::numeric_limits<double>::infinity(), x1 = -x0, y0 = x0, y1 = -x0;
  auto extend = [&](cv::Point2d p) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y)) return;
    x0 = std::min(x0, p.x); x1 = std::max(x1, p.x);
    y0 = std::min(y0, p.y); y1 = std::max(y1, p.y);
  };
  for (const auto& l : lines_) for (const auto& p : l.points) extend(p);
  for (const auto& m : markers_) extend(m.p);
  for (const auto& h : hlines_) { y0 = std::min(y0, h.y); y1 = std::max(y1, h.y); }
  if (!std::isfinite(x0)) { x0 = 0; x1 = 1; y0 = 0; y1 = 1; }
  if (y_from_zero_) y0 = std::min(0.0, y0);
  auto widen = [](double& lo, double& hi) {
    if (hi - lo < 1e-12) { const double c = 0.5 * (lo + hi); lo = c - 0.5; hi = c + 0.5; }
  };
  widen(x0, x1);
  widen(y0, y1);

  // Plot area inside the margins.
  const int left = 80, right = 20, top = title_.empty() ? 20 : 42, bottom = 58;
  const cv::Rect area(left, top, std::max(10, canvas.cols - left - right),
                      std::max(10, canvas.rows - top - bottom));

  if (equal_aspect_) {
    const double pad = 0.04 * std::max(x1 - x0, y1 - y0);
    x0 -= pad; x1 += pad; y0 -= pad; y1 += pad;
    const double sx = (x1 - x0) / area.width, sy = (y1 - y0) / area.height;
    const double s = std::max(sx, sy);  // metres per pixel on both axes
    const double cx = 0.5 * (x0 + x1), cy = 0.5 * (y0 + y1);
    x0 = cx - 0.5 * s * area.width; x1 = cx + 0.5 * s * area.width;
    y0 = cy - 0.5 * s * area.height; y1 = cy + 0.5 * s * area.height;
  } else {
    const double px = 0.02 * (x1 - x0), py = 0.06 * (y1 - y0);
    x0 -= px; x1 += px;
    if (!(y_from_zero_ && y0 >= 0.0)) y0 -= py;
    y1 += py;
  }
  auto to_px = [&](cv::Point2d p) {
    return cv::Point2d(area.x + (p.x - x0) / (x1 - x0) * area.width,
                       area.y + area.height - (p.y - y0) / (y1 - y0) * area.height);
  };

  // Grid, ticks and tick labels.
  const auto xt = nice_ticks(x0, x1, equal_aspect_ ? 6 : 8);
  const auto yt = nice_ticks(y0, y1, 6);
  const double xstep = xt.size() > 1 ? xt[1] - xt[0] : 1.0;
  const double ystep = yt.size() > 1 ? yt[1] - yt[0] : 1.0;
  for (double v : xt) {
    const int px = static_cast<int>(std::lround(to_px({v, y0}).x));
    cv::line(canvas, {px, area.y}, {px, area.y + area.height}, kGrid, 1);
    cv::line(canvas, {px, area.y + area.height}, {px, area.y + area.height + 5}, kBlack, 1);
    const std::string s = tick_label(v, xstep);
    const cv::Size ts = text_size(s, kTickScale);
    put_text(canvas, s, {px - ts.width / 2, area.y + area.height + 8 + ts.height}, kTickScale);
  }
  for (double v : yt) {
    const int py = static_cast<int>(std::lround(to_px({x0, v}).y));
    cv::line(canvas, {area.x, py}, {area.x + area.width, py}, kGrid, 1);
    cv::line(canvas, {area.x - 5, py}, {area.x, py}, kBlack, 1);
    const std::string s = tick_label(v, ystep);
    const cv::Size ts = text_size(s, kTickScale);
    put_text(canvas, s, {area.x - 8 - ts.width, py + ts.height / 2}, kTickScale);
  }

  // Data, clipped to the plot area.
  cv::Mat plot = canvas(area);
  const cv::Point2d origin(area.x, area.y);
  for (const auto& h : hlines_) {
    const double py = to_px({x0, h.y}).y - area.y;
    dashed_line(plot, {0, py}, {static_cast<double>(area.width), py}, h.style);
  }
  constexpr int kShift = 4;  // sub-pixel precision for polylines
  std::vector<cv::Point> drawn;  // plot-area pixels with data, to keep the legend off them
  for (const auto& l : lines_) {
    std::vector<cv::Point> pts;
    pts.reserve(l.points.size());
    for (const auto& p : l.points) {
      const cv::Point2d q = (to_px(p) - origin) * (1 << kShift);
      pts.emplace_back(static_cast<int>(std::lround(q.x)), static_cast<int>(std::lround(q.y)));
    }
    const std::size_t stride = std::max<std::size_t>(1, pts.size() / 5000);
    for (std::size_t i = 0; i < pts.size(); i += stride) drawn.emplace_back(pts[i].x >> kShift, pts[i].y >> kShift);
    if (pts.size() == 1) {
      cv::circle(plot, pts[0], 3 << kShift, l.style.color, cv::FILLED, cv::LINE_AA, kShift);
    } else if (l.style.dashed) {
      for (std::size_t i = 1; i < l.points.size(); i += 2) {
        cv::line(plot, pts[i - 1], pts[i], l.style.color, l.style.thickness, cv::LINE_AA, kShift);
      }
    } else {
      cv::polylines(plot, pts, false, l.style.color, l.style.thickness, cv::LINE_AA, kShift);
    }
  }
  for (const auto& m : markers_) {
    const cv::Point c = to_px(m.p) - origin;
    cv::rectangle(plot, c - cv::Point(6, 6), c + cv::Point(6, 6), m.color, 2, cv::LINE_AA);
  }
  cv::rectangle(canvas, area, kBlack, 1);

  // Labels and title.
  if (!xlabel_.empty()) {
    const cv::Size ts = text_size(xlabel_, kLabelScale);
    put_text(canvas, xlabel_, {area.x + area.width / 2 - ts.width / 2, canvas.rows - 10}, kLabelScale);
  }
  if (!ylabel_.empty()) put_vertical_text(canvas, ylabel_, {16, area.y + area.height / 2}, kLabelScale);
  if (!title_.empty()) {
    const cv::Size ts = text_size(title_, kTitleScale, 2);
    put_text(canvas, title_, {area.x + area.width / 2 - ts.width / 2, 28}, kTitleScale, 1);
  }

  // Legend in the top-right corner of the plot area.
  std::vector<std::pair<std::string, LineStyle>> entries;
  for (const auto& l : lines_) if (!l.label.empty()) entries.emplace_back(l.label, l.style);
  for (const auto& h : hlines_) if (!h.label.empty()) entries.emplace_back(h.label, h.style);
  std::vector<const Marker*> marker_entries;
  for (const auto& m : markers_) if (!m.label.empty()) marker_entries.push_back(&m);
  const std::size_t n = entries.size() + marker_entries.size();
  if (n == 0) return;
  int width = 0;
  for (const auto& e : entries) width = std::max(width, text_size(e.first, kTickScale).width);
  for (const auto* m : marker_entries) width = std::max(width, text_size(m->label, kTickScale).width);
  const int row = 20;
  const cv::Size box_size(width + 54, static_cast<int>(n) * row + 8);
  // The corner of the plot area that hides the fewest data points (top-right on a tie).
  const int xr = area.width - box_size.width - 8, yb = area.height - box_size.height - 8;
  const std::array<cv::Point, 4> corners = {cv::Point(xr, 8), cv::Point(8, 8), cv::Point(xr, yb), cv::Point(8, yb)};
  std::size_t best_hidden = std::numeric_limits<std::size_t>::max();
  cv::Rect box;
  for (const auto& c : corners) {
    const cv::Rect candidate(c, box_size);
    const auto hidden = static_cast<std::size_t>(std::count_if(
        drawn.begin(), drawn.end(), [&](const cv::Point& p) { return candidate.contains(p); }));
    if (hidden < best_hidden) {
      best_hidden = hidden;
      box = candidate + area.tl();
    }
  }
  box &= cv::Rect(0, 0, canvas.cols, canvas.rows);
  canvas(box).setTo(kWhite);
  cv::rectangle(canvas, box, cv::Scalar(160, 160, 160), 1);
  int y = box.y + 4 + row / 2;
  for (const auto& [label, style] : entries) {
    LineStyle s = style;
    s.thickness = std::max(2, s.thickness);
    dashed_line(canvas, {box.x + 8.0, y + 0.0}, {box.x + 40.0, y + 0.0}, s);
    put_text(canvas, label, {box.x + 48, y + 5}, kTickScale);
    y += row;
  }
  for (const auto* m : marker_entries) {
    cv::rectangle(canvas, cv::Point(box.x + 18, y - 6), cv::Point(box.x + 30, y + 6), m->color, 2, cv::LINE_AA);
    put_text(canvas, m->label, {box.x + 48, y + 5}, kTickScale);
    y += row;
  }
}

}  // namespace plslam::eval
