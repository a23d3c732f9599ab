#include "skelgraph/calib/board.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include <Eigen/SVD>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "skelgraph/calib/rigid.hpp"

namespace skelgraph::calib {

using Eigen::Vector3d;

Board Board::parse(const std::string& size, double square_m) {
  Board b;
  char x = 0;
  char extra = 0;
  if (std::sscanf(size.c_str(), "%d%c%d%c", &b.cols, &x, &b.rows, &extra) != 3 || (x != 'x' && x != 'X') || b.cols < 3 ||
      b.rows < 3) {
    throw CalibError("board size '" + size + "': expected inner corners as COLSxROWS, e.g. 9x6 (each at least 3)");
  }
  if (!(square_m > 0)) throw CalibError("board square size must be > 0 m");
  b.square_m = square_m;
  return b;
}

std::vector<Vector3d> Board::object_points() const {
  std::vector<Vector3d> p;
  for (int j = 0; j < rows; ++j) {
    for (int i = 0; i < cols; ++i) p.emplace_back(i * square_m, j * square_m, 0.0);
  }
  return p;
}

namespace {
// OpenCV views of skelgraph's images (no copy) and back.
cv::Mat as_mat(const GreyImage& g) {
  return cv::Mat(g.height, g.width, CV_8U, const_cast<std::uint8_t*>(g.pixels.data()));
}
cv::Mat as_mat(const DepthImageMm& d) { return cv::Mat(d.height, d.width, CV_16U, const_cast<std::uint16_t*>(d.mm.data())); }
GreyImage grey_of(const cv::Mat& m) {
  GreyImage g;
  g.width = m.cols, g.height = m.rows;
  g.pixels.resize(static_cast<std::size_t>(m.cols) * static_cast<std::size_t>(m.rows));
  for (int v = 0; v < m.rows; ++v) std::copy_n(m.ptr<std::uint8_t>(v), m.cols, g.pixels.data() + static_cast<std::size_t>(v) * m.cols);
  return g;
}
std::vector<cv::Point2f> points_of(const Corners& c) {
  std::vector<cv::Point2f> p;
  p.reserve(c.size());
  for (const auto& x : c) p.emplace_back(x.x(), x.y());
  return p;
}

// Mean grey level of a small patch around a point.
double grey_at(const cv::Mat& grey, cv::Point2f p) {
  cv::Mat patch;
  cv::getRectSubPix(grey, cv::Size(3, 3), p, patch, CV_32F);
  return cv::mean(patch)[0];
}
}  // namespace

GreyImage read_grey_image(const std::string& path) {
  const cv::Mat m = cv::imread(path, cv::IMREAD_GRAYSCALE);
  if (m.empty()) throw CalibError(path + ": cannot read the image (missing, or not an image OpenCV reads)");
  return grey_of(m);
}

DepthImageMm read_depth_image(const std::string& path) {
  const cv::Mat m = cv::imread(path, cv::IMREAD_ANYDEPTH);
  if (m.empty()) throw CalibError(path + ": cannot read the image (missing, or not an image OpenCV reads)");
  if (m.type() != CV_16U) throw CalibError(path + ": expected a 16-bit depth image (millimetres)");
  DepthImageMm d;
  d.width = m.cols, d.height = m.rows;
  d.mm.resize(static_cast<std::size_t>(m.cols) * static_cast<std::size_t>(m.rows));
  for (int v = 0; v < m.rows; ++v) std::copy_n(m.ptr<std::uint16_t>(v), m.cols, d.mm.data() + static_cast<std::size_t>(v) * m.cols);
  return d;
}

void write_png(const std::string& path, const GreyImage& image) {
  if (!cv::imwrite(path, as_mat(image))) throw CalibError(path + ": cannot write the image");
}
void write_png(const std::string& path, const DepthImageMm& image) {
  if (!cv::imwrite(path, as_mat(image))) throw CalibError(path + ": cannot write the image");
}

std::optional<Corners> find_corners(const GreyImage& grey_image, const Board& board) {
  const cv::Mat grey = as_mat(grey_image);
  std::vector<cv::Point2f> corners;
  const cv::Size pattern(board.cols, board.rows);
  if (!cv::findChessboardCorners(grey, pattern, corners,
                                 cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE | cv::CALIB_CB_FAST_CHECK)) {
    return std::nullopt;
  }
  // The refinement window must stay inside one square's corner region.
  double spacing = 0;
  for (int j = 0; j < board.rows; ++j) {
    for (int i = 0; i + 1 < board.cols; ++i) spacing += cv::norm(corners[j * board.cols + i + 1] - corners[j * board.cols + i]);
  }
  spacing /= board.rows * (board.cols - 1);
  const int half = std::clamp(static_cast<int>(0.3 * spacing), 2, 6);
  cv::cornerSubPix(grey, corners, cv::Size(half, half), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 50, 0.001));
  // findChessboardCorners cannot tell a board from itself turned by 180
  // degrees; the colours can (COLSxROWS with one odd, one even): the square
  // between the first four corners is dark.
  const int c = board.cols;
  const auto centre = [&](int a) { return (corners[a] + corners[a + 1] + corners[a + c] + corners[a + c + 1]) * 0.25f; };
  if (grey_at(grey, centre(0)) > grey_at(grey, centre(1))) std::reverse(corners.begin(), corners.end());
  Corners out;
  out.reserve(corners.size());
  for (const auto& p : corners) out.emplace_back(p.x, p.y);
  return out;
}

IntrinsicsResult calibrate_intrinsics(const std::vector<Corners>& views, const Board& board, int width, int height) {
  const cv::Size image_size(width, height);
  std::vector<std::vector<cv::Point2f>> corners;
  for (const auto& v : views) corners.push_back(points_of(v));
  if (corners.size() < 3) {
    throw CalibError("need the board in at least 3 images for intrinsics, found it in " + std::to_string(corners.size()));
  }
  std::vector<cv::Point3f> obj;
  for (const auto& p : board.object_points()) obj.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()), 0.f);
  const std::vector<std::vector<cv::Point3f>> objs(corners.size(), obj);
  cv::Mat K, dist;
  std::vector<cv::Mat> rvecs, tvecs;
  IntrinsicsResult r;
  r.rms_reprojection_px = cv::calibrateCamera(objs, corners, image_size, K, dist, rvecs, tvecs, cv::CALIB_FIX_K3);
  r.views = corners.size();
  r.intrinsics.width = image_size.width;
  r.intrinsics.height = image_size.height;
  r.intrinsics.fx = K.at<double>(0, 0);
  r.intrinsics.fy = K.at<double>(1, 1);
  r.intrinsics.cx = K.at<double>(0, 2);
  r.intrinsics.cy = K.at<double>(1, 2);
  for (int i = 0; i < static_cast<int>(dist.total()); ++i) r.intrinsics.distortion.push_back(dist.at<double>(i));
  return r;
}

LiftedCorners lift_corners(const Corners& corners, const DepthImageMm& depth, const Intrinsics& k, const Board& board) {
  if (depth.mm.size() != static_cast<std::size_t>(depth.width) * static_cast<std::size_t>(depth.height)) {
    throw CalibError("depth image: " + std::to_string(depth.mm.size()) + " readings for " + std::to_string(depth.width) + "x" +
                     std::to_string(depth.height));
  }
  if (corners.size() != static_cast<std::size_t>(board.cols * board.rows)) throw CalibError("corner count does not match the board");
  // The outline of the inner corners: the board is certainly there.
  const int c = board.cols, last = board.cols * board.rows - 1;
  std::vector<cv::Point> outline;
  for (int i : {0, c - 1, last, last - c + 1}) outline.emplace_back(cvRound(corners[i].x()), cvRound(corners[i].y()));
  cv::Mat mask = cv::Mat::zeros(depth.height, depth.width, CV_8U);
  cv::fillConvexPoly(mask, outline, cv::Scalar(255));
  std::vector<Vector3d> pts;
  for (int v = 0; v < depth.height; ++v) {
    for (int u = 0; u < depth.width; ++u) {
      const auto d = depth.mm[static_cast<std::size_t>(v) * depth.width + u];
      if (d == 0 || mask.at<std::uint8_t>(v, u) == 0) continue;
      pts.push_back(k.ray(u, v) * (d / 1000.0));
    }
  }
  LiftedCorners out;
  if (pts.size() < 50) {
    throw CalibError("only " + std::to_string(pts.size()) + " depth readings on the board (need 50): is the depth image registered to the colour image?");
  }
  // Plane by SVD; twice more without the readings far from it.
  Vector3d centroid = Vector3d::Zero(), normal = Vector3d::UnitZ();
  std::vector<Vector3d> use = pts;
  for (int round = 0; round < 3; ++round) {
    centroid.setZero();
    for (const auto& p : use) centroid += p;
    centroid /= static_cast<double>(use.size());
    Eigen::MatrixXd M(use.size(), 3);
    for (std::size_t i = 0; i < use.size(); ++i) M.row(static_cast<Eigen::Index>(i)) = (use[i] - centroid).transpose();
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(M, Eigen::ComputeThinV);
    normal = svd.matrixV().col(2);
    double ss = 0;
    for (const auto& p : use) ss += std::pow(normal.dot(p - centroid), 2);
    const double rms = std::sqrt(ss / static_cast<double>(use.size()));
    out.plane_rms_m = rms;
    std::vector<Vector3d> keep;
    for (const auto& p : pts) {
      if (std::abs(normal.dot(p - centroid)) <= 3.0 * rms + 1e-4) keep.push_back(p);
    }
    if (keep.size() < 50) break;
    use = std::move(keep);
  }
  out.depth_pixels = use.size();
  for (const auto& p : corners) {
    const Vector3d r = k.ray(p.x(), p.y());
    const double den = normal.dot(r);
    if (std::abs(den) < 1e-9) throw CalibError("the board is seen edge-on");
    out.points.push_back(r * (normal.dot(centroid) / den));
  }
  return out;
}

BoardView render_board_view(const Board& board, const Intrinsics& k, const Eigen::Isometry3d& camera_from_board,
                            double grey_noise, double depth_noise_scale, std::uint64_t seed) {
  // The board as a texture: (cols+1) x (rows+1) squares, a white margin of one square.
  const int px = 48, margin = 1;
  const int tw = (board.cols + 1 + 2 * margin) * px, th = (board.rows + 1 + 2 * margin) * px;
  cv::Mat tex(th, tw, CV_8U, cv::Scalar(235));
  for (int j = 0; j <= board.rows; ++j) {
    for (int i = 0; i <= board.cols; ++i) {
      if ((i + j) % 2 == 0) cv::rectangle(tex, cv::Rect((i + margin) * px, (j + margin) * px, px, px), cv::Scalar(20), cv::FILLED);
    }
  }
  // Texture pixel -> board coordinates (m): inner corner (0, 0) sits on the
  // boundary between texture pixels (margin + 1) * px - 1 and (margin + 1) * px.
  const double s = board.square_m / px, o = ((margin + 1) * px - 0.5) * s;
  Eigen::Matrix3d A;
  A << s, 0, -o, 0, s, -o, 0, 0, 1;
  const Eigen::Matrix3d R = camera_from_board.rotation();
  const Vector3d t = camera_from_board.translation();
  Eigen::Matrix3d P;
  P.col(0) = R.col(0);
  P.col(1) = R.col(1);
  P.col(2) = t;
  Eigen::Matrix3d K;
  K << k.fx, 0, k.cx, 0, k.fy, k.cy, 0, 0, 1;
  const Eigen::Matrix3d H = K * P * A;
  cv::Mat Hcv(3, 3, CV_64F);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) Hcv.at<double>(r, c) = H(r, c);
  }
  cv::Mat grey;
  cv::warpPerspective(tex, grey, Hcv, cv::Size(k.width, k.height), cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(110));
  cv::GaussianBlur(grey, grey, cv::Size(0, 0), 0.7);
  cv::RNG rng(seed);
  cv::Mat noise(grey.size(), CV_32F);
  rng.fill(noise, cv::RNG::NORMAL, 0.0, grey_noise);
  cv::Mat g;
  grey.convertTo(g, CV_32F);
  g += noise;
  g.convertTo(grey, CV_8U);
  BoardView view;
  view.grey = grey_of(grey);
  // Depth: each pixel's ray cut with the board's plane, where it hits the board.
  view.depth_mm.width = k.width, view.depth_mm.height = k.height;
  view.depth_mm.mm.assign(static_cast<std::size_t>(k.width) * static_cast<std::size_t>(k.height), 0);
  const Vector3d n = R.col(2);
  const double lo_x = -(margin + 1) * board.square_m, hi_x = (board.cols + margin) * board.square_m;
  const double lo_y = -(margin + 1) * board.square_m, hi_y = (board.rows + margin) * board.square_m;
  for (int v = 0; v < k.height; ++v) {
    for (int u = 0; u < k.width; ++u) {
      const Vector3d d = k.ray(u, v);
      const double den = n.dot(d);
      if (std::abs(den) < 1e-9) continue;
      const double lambda = n.dot(t) / den;
      if (lambda <= 0) continue;
      const Vector3d q = R.transpose() * (lambda * d - t);
      if (q.x() < lo_x || q.x() > hi_x || q.y() < lo_y || q.y() > hi_y) continue;
      const double z = lambda;  // d.z() == 1
      const double sd = depth_noise_scale * (0.0012 + 0.0019 * (z - 0.4) * (z - 0.4));
      const double mm = std::round((z + rng.gaussian(sd)) * 1000.0);
      if (mm > 0 && mm < 65535) view.depth_mm.mm[static_cast<std::size_t>(v) * k.width + u] = static_cast<std::uint16_t>(mm);
    }
  }
  return view;
}

std::vector<std::string> board_view_names(const std::string& dir) {
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(dir, ec)) {
    const auto f = e.path().filename().string();
    const std::string tail = "_color.png";
    if (f.size() > tail.size() && f.compare(f.size() - tail.size(), tail.size(), tail) == 0) {
      names.push_back(f.substr(0, f.size() - tail.size()));
    }
  }
  if (ec) throw CalibError(dir + ": " + ec.message());
  std::sort(names.begin(), names.end());
  return names;
}

std::optional<std::vector<Eigen::Vector3d>> lift_board_view(const std::string& dir, const std::string& name,
                                                            const Board& board, const Intrinsics& k, std::string* why) {
  const std::filesystem::path d = dir;
  const auto colour = (d / (name + "_color.png")).string(), depth = (d / (name + "_depth.png")).string();
  if (!std::filesystem::exists(colour) || !std::filesystem::exists(depth)) {
    *why = name + ": no colour and depth image in " + dir;
    return std::nullopt;
  }
  const auto corners = find_corners(read_grey_image(colour), board);
  if (!corners) {
    *why = name + ": board not found in " + colour;
    return std::nullopt;
  }
  const auto depth_image = read_depth_image(depth);
  try {
    return lift_corners(*corners, depth_image, k, board).points;
  } catch (const CalibError& e) {
    *why = name + ": " + e.what();
    return std::nullopt;
  }
}

Eigen::Isometry3d camera_from_board(const Eigen::Isometry3d& world_from_sensor, const Eigen::Isometry3d& world_from_board) {
  Eigen::Isometry3d camera_from_sensor = Eigen::Isometry3d::Identity();
  camera_from_sensor.linear() = sensor_from_camera().transpose();
  return camera_from_sensor * world_from_sensor.inverse() * world_from_board;
}

std::vector<Eigen::Isometry3d> board_poses_seen_by(const std::vector<Eigen::Isometry3d>& world_from_sensors,
                                                   const Board& board, const Intrinsics& k, int count,
                                                   const Vector3d& centre, std::uint64_t seed) {
  cv::RNG rng(seed);
  Vector3d towards = Vector3d::Zero();  // the mean direction to the sensors, level
  for (const auto& s : world_from_sensors) {
    Vector3d d = s.translation() - centre;
    d.y() = 0;
    towards += d.normalized();
  }
  if (towards.norm() < 1e-6) towards = Vector3d::UnitZ();
  towards.normalize();
  const Vector3d middle = 0.5 * Vector3d((board.cols - 1) * board.square_m, (board.rows - 1) * board.square_m, 0);
  std::vector<Eigen::Isometry3d> out;
  for (int tries = 0; static_cast<int>(out.size()) < count && tries < 100000; ++tries) {
    // Front (the printed side) towards the sensors, tilted and turned a little.
    const Eigen::Matrix3d tilt = (Eigen::AngleAxisd(rng.uniform(-0.5, 0.5), Vector3d::UnitY()) *
                                  Eigen::AngleAxisd(rng.uniform(-0.35, 0.35), Vector3d::UnitX()))
                                     .toRotationMatrix();
    const Vector3d z = -(tilt * towards).normalized();  // the board's z points away from the viewer
    const Vector3d x = (-Vector3d::UnitY()).cross(z).normalized();
    const Vector3d y = z.cross(x);
    Eigen::Matrix3d R;
    R.col(0) = x, R.col(1) = y, R.col(2) = z;
    R = R * Eigen::AngleAxisd(rng.uniform(-0.3, 0.3), Vector3d::UnitZ()).toRotationMatrix();
    const Vector3d c = centre + Vector3d(rng.uniform(-0.5, 0.5), rng.uniform(-0.35, 0.35), rng.uniform(-0.5, 0.5));
    Eigen::Isometry3d wb = Eigen::Isometry3d::Identity();
    wb.linear() = R;
    wb.translation() = c - R * middle;
    bool ok = true;
    for (const auto& ws : world_from_sensors) ok = ok && board_in_view(ws, wb, board, k);
    if (ok) out.push_back(wb);
  }
  if (static_cast<int>(out.size()) < count) throw CalibError("the sensors do not see a common place for the board");
  return out;
}

bool board_in_view(const Eigen::Isometry3d& world_from_sensor, const Eigen::Isometry3d& world_from_board,
                   const Board& board, const Intrinsics& k) {
  const Vector3d middle = 0.5 * Vector3d((board.cols - 1) * board.square_m, (board.rows - 1) * board.square_m, 0);
  const auto cb = camera_from_board(world_from_sensor, world_from_board);
  const Vector3d front = -cb.rotation().col(2), to_camera = -(cb * middle);
  if (front.dot(to_camera.normalized()) < std::cos(45.0 * M_PI / 180)) return false;
  for (const auto& p : board.object_points()) {
    const Vector3d q = cb * p;
    if (q.z() < 0.8 || q.z() > 3.0) return false;
    const double u = k.fx * q.x() / q.z() + k.cx, v = k.fy * q.y() / q.z() + k.cy;
    if (u < 20 || v < 20 || u > k.width - 20 || v > k.height - 20) return false;
  }
  return true;
}

}  // namespace skelgraph::calib
