#include "common/grid_udf.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <sys/stat.h>

#include "common/atomic_file.h"
#include "common/errors.h"
#include "common/input_file.h"
#include "common/udf_spec.h"

#include <Eigen/Eigenvalues>

namespace voroudf {
namespace {

// Below kNormalBand grid spacings from the zero set the gradient comes from the Hessian of q (see EvaluateChunk).
constexpr double kNormalBand = 0.25;

bool FileExists(const std::string& path) {
  struct stat st;
  return ::stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

// The value of key `key` in NumPy's header, a Python dict literal such as
// {'descr': '<f4', 'fortran_order': False, 'shape': (64, 64, 64), }: the text up to the next top-level ','.
std::string HeaderValue(const std::string& header, const std::string& key, const std::string& path) {
  size_t pos = header.find("'" + key + "'");
  if (pos == std::string::npos) pos = header.find("\"" + key + "\"");
  if (pos == std::string::npos) throw InputError(path, "NumPy header has no '" + key + "' (not a .npy file?)");
  pos = header.find(':', pos);
  if (pos == std::string::npos) throw InputError(path, "malformed NumPy header");
  ++pos;
  int depth = 0;
  size_t end = pos;
  for (; end < header.size(); ++end) {
    const char c = header[end];
    if (c == '(' || c == '[') ++depth;
    if (c == ')' || c == ']') --depth;
    if ((c == ',' && depth == 0) || c == '}') break;
  }
  std::string v = header.substr(pos, end - pos);
  const auto first = v.find_first_not_of(" \t");
  const auto last = v.find_last_not_of(" \t");
  return first == std::string::npos ? "" : v.substr(first, last - first + 1);
}

// Catmull-Rom (Keys a = -1/2) weights and their derivatives for the samples at i0-1 .. i0+2, folded so that
// the ghost nodes -1 and n (linear extrapolation: f(-1) = 2 f(0) - f(1)) become weights on real nodes.
struct Stencil {
  size_t idx[4];
  double w[4], dw[4], ddw[4];
};

Stencil AxisStencil(double u, size_t n) {
  // u is the position in grid units, already clamped to [0, n - 1]; n >= 2.
  size_t i0 = static_cast<size_t>(std::floor(u));
  if (i0 > n - 2) i0 = n - 2;
  const double t = u - static_cast<double>(i0);
  const double t2 = t * t, t3 = t2 * t;
  Stencil s;
  s.w[0] = 0.5 * (-t3 + 2 * t2 - t);
  s.w[1] = 0.5 * (3 * t3 - 5 * t2 + 2);
  s.w[2] = 0.5 * (-3 * t3 + 4 * t2 + t);
  s.w[3] = 0.5 * (t3 - t2);
  s.dw[0] = 0.5 * (-3 * t2 + 4 * t - 1);
  s.dw[1] = 0.5 * (9 * t2 - 10 * t);
  s.dw[2] = 0.5 * (-9 * t2 + 8 * t + 1);
  s.dw[3] = 0.5 * (3 * t2 - 2 * t);
  s.ddw[0] = -3 * t + 2;
  s.ddw[1] = 9 * t - 5;
  s.ddw[2] = -9 * t + 4;
  s.ddw[3] = 3 * t - 1;
  s.idx[1] = i0;
  s.idx[2] = i0 + 1;
  s.idx[0] = i0 > 0 ? i0 - 1 : i0;
  s.idx[3] = i0 + 2 < n ? i0 + 2 : i0 + 1;
  // Ghost nodes -1 and n by quadratic extrapolation, f(-1) = 3 f(0) - 3 f(1) + f(2), which keeps Keys'
  // third order up to the box faces (the boundary condition of Keys 1981); linear with only 2 samples.
  auto fold = [&s](int ghost, int e0, int e1, int e2, bool quadratic) {
    const double c0 = quadratic ? 3.0 : 2.0, c1 = quadratic ? -3.0 : -1.0, c2 = quadratic ? 1.0 : 0.0;
    double* arrays[3] = {s.w, s.dw, s.ddw};
    for (double* a : arrays) {
      a[e0] += c0 * a[ghost], a[e1] += c1 * a[ghost], a[e2] += c2 * a[ghost];
      a[ghost] = 0.0;
    }
  };
  if (i0 == 0) fold(0, 1, 2, 3, n >= 3);        // entries 1, 2, 3 are nodes 0, 1, 2
  if (i0 + 2 >= n) fold(3, 2, 1, 0, n >= 3);    // entries 2, 1, 0 are nodes n-1, n-2, n-3
  return s;
}

}  // namespace

namespace {

// Where the header of a .npy file ends (the data's offset), from its first bytes `pre` (at least 12, or
// the whole file if shorter); `file_size` is the size of the whole file.
size_t NpyHeaderEnd(const std::string& pre, size_t file_size, const std::string& path) {
  if (file_size < 10 || pre.size() < 10 || std::memcmp(pre.data(), "\x93NUMPY", 6) != 0)
    throw InputError(path, "not a NumPy .npy file (no \\x93NUMPY magic)");
  const int major = static_cast<unsigned char>(pre[6]);
  size_t header_len, offset;
  if (major == 1) {
    header_len = static_cast<unsigned char>(pre[8]) | (static_cast<size_t>(static_cast<unsigned char>(pre[9])) << 8);
    offset = 10;
  } else if (major == 2 || major == 3) {
    if (file_size < 12 || pre.size() < 12) throw InputError(path, "truncated NumPy header");
    uint32_t len;
    std::memcpy(&len, pre.data() + 8, 4);
    header_len = len;
    offset = 12;
  } else {
    throw InputError(path, "unsupported .npy format version " + std::to_string(major) + " (expected 1, 2 or 3)");
  }
  if (file_size < offset + header_len) throw InputError(path, "truncated NumPy header");
  return offset + header_len;
}

struct NpyLayout {
  std::vector<size_t> shape;
  size_t data_offset = 0;
  size_t count = 1;
};

// The layout from `head`, the file's bytes up to at least NpyHeaderEnd; checks the data against file_size.
NpyLayout ParseNpyLayout(const std::string& head, size_t file_size, const std::string& path) {
  NpyLayout layout;
  layout.data_offset = NpyHeaderEnd(head, file_size, path);
  const size_t begin = static_cast<unsigned char>(head[6]) == 1 ? 10 : 12;
  const std::string header = head.substr(begin, layout.data_offset - begin);
  std::string descr = HeaderValue(header, "descr", path);
  descr.erase(std::remove_if(descr.begin(), descr.end(), [](char c) { return c == '\'' || c == '"'; }), descr.end());
  if (descr != "<f4" && descr != "|f4")
    throw InputError(path, "dtype '" + descr + "' is not supported: expected little-endian float32 ('<f4'); "
                           "save with arr.astype('<f4')");
  const std::string fortran = HeaderValue(header, "fortran_order", path);
  if (fortran != "False")
    throw InputError(path, "the array is in Fortran order: expected C order (save np.ascontiguousarray(arr))");
  const std::string shape_text = HeaderValue(header, "shape", path);
  std::string digits;
  auto flush = [&] {
    if (digits.empty()) return;
    if (digits.size() > 12) throw InputError(path, "array too large: shape " + shape_text);
    layout.shape.push_back(std::stoull(digits));
    digits.clear();
  };
  for (char c : shape_text) {
    if (std::isdigit(static_cast<unsigned char>(c))) {
      digits += c;
      continue;
    }
    flush();
    if (c != '(' && c != ')' && c != ',' && c != ' ' && c != 'L')
      throw InputError(path, "malformed shape " + shape_text + " in the NumPy header");
  }
  flush();
  for (size_t n : layout.shape) {
    if (n != 0 && layout.count > (size_t(1) << 40) / n) throw InputError(path, "array too large: shape " + shape_text);
    layout.count *= n;
  }
  const size_t need = layout.count * sizeof(float), have = file_size - layout.data_offset;
  if (have < need)
    throw InputError(path, "truncated: shape " + shape_text + " needs " + std::to_string(need) +
                               " data bytes, the file has " + std::to_string(have));
  if (have > need)
    throw InputError(path, "has " + std::to_string(have - need) + " bytes after the array of shape " + shape_text);
  return layout;
}

}  // namespace

NpyArray ParseNpyFloat32(const std::string& bytes, const std::string& name) {
  const NpyLayout layout = ParseNpyLayout(bytes, bytes.size(), name);
  NpyArray array;
  array.shape = layout.shape;
  array.data.resize(layout.count);
  if (layout.count > 0) std::memcpy(array.data.data(), bytes.data() + layout.data_offset, layout.count * sizeof(float));
  return array;
}

NpyArray ReadNpyFloat32(const std::string& path) {
  // The header is read first and the data straight into the array: a 512^3 grid is 512 MB, no copy.
  CheckInputFile(path);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, std::string("cannot open: ") + std::strerror(errno));
  in.seekg(0, std::ios::end);
  const size_t file_size = static_cast<size_t>(in.tellg());
  in.seekg(0);
  std::string head(std::min<size_t>(12, file_size), '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(NpyHeaderEnd(head, file_size, path));
  in.seekg(0);
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  const NpyLayout layout = ParseNpyLayout(head, file_size, path);
  NpyArray array;
  array.shape = layout.shape;
  array.data.resize(layout.count);
  // The machine is little-endian (x86-64, arm64), like '<f4'.
  in.read(reinterpret_cast<char*>(array.data.data()), static_cast<std::streamsize>(layout.count * sizeof(float)));
  if (!in) throw InputError(path, "read error in the array data");
  return array;
}

void WriteNpyFloat32(const std::string& path, const std::vector<size_t>& shape, const std::vector<float>& data) {
  std::string dims;
  for (size_t s : shape) dims += std::to_string(s) + ", ";
  if (shape.size() > 1) dims.erase(dims.size() - 2);
  else if (shape.size() == 1) dims.erase(dims.size() - 1);
  std::string header = "{'descr': '<f4', 'fortran_order': False, 'shape': (" + dims + "), }";
  // Magic (6) + version (2) + length (2) + header + '\n' is padded to a multiple of 64 bytes.
  const size_t total = 10 + header.size() + 1;
  header.append((64 - total % 64) % 64, ' ');
  header += '\n';
  std::string bytes("\x93NUMPY\x01\x00", 8);
  bytes += static_cast<char>(header.size() & 0xff);
  bytes += static_cast<char>(header.size() >> 8);
  bytes += header;
  bytes.append(reinterpret_cast<const char*>(data.data()), data.size() * sizeof(float));
  WriteFileAtomically(path, bytes);
}

Box ParseBoxOption(const std::string& text) {
  std::vector<double> v;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    char* end = nullptr;
    const double x = std::strtod(item.c_str(), &end);
    if (item.empty() || end == item.c_str() || end != item.c_str() + item.size() || !std::isfinite(x))
      throw UsageError("--udf-box '" + text + "': expected six numbers xmin,ymin,zmin,xmax,ymax,zmax");
    v.push_back(x);
  }
  if (v.size() != 6) throw UsageError("--udf-box '" + text + "': expected six numbers xmin,ymin,zmin,xmax,ymax,zmax");
  Box box{Vec3(v[0], v[1], v[2]), Vec3(v[3], v[4], v[5])};
  if (!(box.min.array() < box.max.array()).all())
    throw UsageError("--udf-box '" + text + "': each min must be below its max");
  if (!std::isfinite(box.Diagonal())) throw UsageError("--udf-box '" + text + "': the box's diagonal overflows");
  return box;
}

Box ReadBoxJson(const std::string& path) { return ParseBoxJson(ReadInputBytes(path), path); }

Box ParseBoxJson(const std::string& text, const std::string& path) {
  const size_t key = text.find("\"box\"");
  if (key == std::string::npos) throw InputError(path, "no \"box\" key (expected {\"box\": [[x0,y0,z0],[x1,y1,z1]]})");
  size_t pos = key + 5;
  auto expect = [&](char c) {
    while (pos < text.size() && std::isspace(static_cast<unsigned char>(text[pos]))) ++pos;
    if (pos >= text.size() || text[pos] != c)
      throw InputError(path, std::string("malformed \"box\": expected '") + c + "' (format {\"box\": [[x0,y0,z0],[x1,y1,z1]]})");
    ++pos;
  };
  auto number = [&]() {
    while (pos < text.size() && std::isspace(static_cast<unsigned char>(text[pos]))) ++pos;
    const char* start = text.c_str() + pos;
    char* end = nullptr;
    const double x = std::strtod(start, &end);
    if (end == start || !std::isfinite(x)) throw InputError(path, "malformed \"box\": expected a finite number");
    pos += static_cast<size_t>(end - start);
    return x;
  };
  expect(':');
  expect('[');
  Vec3 corner[2];
  for (int c = 0; c < 2; ++c) {
    if (c == 1) expect(',');
    expect('[');
    for (int k = 0; k < 3; ++k) {
      if (k > 0) expect(',');
      corner[c][k] = number();
    }
    expect(']');
  }
  expect(']');
  if (!(corner[0].array() < corner[1].array()).all())
    throw InputError(path, "\"box\": each min must be below its max");
  const Box box{corner[0], corner[1]};
  // Every length in voroudf is relative to the diagonal: it must be a finite number.
  if (!std::isfinite(box.Diagonal())) throw InputError(path, "\"box\": its diagonal overflows (box too large)");
  return box;
}

GridUdf::GridUdf(const std::vector<float>& values, std::array<size_t, 3> dims, const Box& box,
                 std::vector<float> gradient, std::string name)
    : gradient_(std::move(gradient)), dims_(dims), box_(box), name_(std::move(name)) {
  for (size_t n : dims_)
    if (n < 2) throw InputError(name_, "every grid axis needs at least 2 samples (shape " + std::to_string(dims_[0]) +
                                           "x" + std::to_string(dims_[1]) + "x" + std::to_string(dims_[2]) + ")");
  const size_t count = dims_[0] * dims_[1] * dims_[2];
  if (values.size() != count) throw InputError(name_, "grid has " + std::to_string(values.size()) + " values, expected " + std::to_string(count));
  if (!gradient_.empty() && gradient_.size() != 3 * count)
    throw InputError(name_, "gradient array has " + std::to_string(gradient_.size()) + " values, expected 3 * " + std::to_string(count));
  if (!(box_.min.array() < box_.max.array()).all()) throw InputError(name_, "the grid's box is empty");
  if (!std::isfinite(box_.Diagonal())) throw InputError(name_, "the grid's box is too large (its diagonal overflows)");
  q_.resize(count);
  // A distance sampled in the box is at most its diagonal where the surface lies in it; a million times
  // that is no distance at all, and its square (kept as float) would overflow the interpolation.
  const double largest = std::min(1e6 * box_.Diagonal(), 1e15);
  for (size_t i = 0; i < count; ++i) {
    if (!std::isfinite(values[i])) throw InputError(name_, "sample " + std::to_string(i) + " is not finite");
    const double d = std::max(0.0, static_cast<double>(values[i]));
    if (d > largest) {
      char buf[120];
      std::snprintf(buf, sizeof buf, "sample %zu is %g, more than a million box diagonals (%g): not a distance", i,
                    d, box_.Diagonal());
      throw InputError(name_, buf);
    }
    q_[i] = static_cast<float>(d * d);
  }
  for (float g : gradient_)
    if (!std::isfinite(g)) throw InputError(name_, "the gradient array has a non-finite value");
  for (int k = 0; k < 3; ++k) h_[k] = box_.Extent()[k] / static_cast<double>(dims_[k] - 1);
}

std::unique_ptr<GridUdf> GridUdf::Open(const std::string& path, const std::string& box_option) {
  Box box;
  std::string box_source;
  const std::string json = path.substr(0, path.size() - 4) + ".json";
  if (!box_option.empty()) {
    box = ParseBoxOption(box_option);
    box_source = "--udf-box";
  } else if (FileExists(json)) {
    box = ReadBoxJson(json);
    box_source = json;
  } else {
    throw InputError(path, "no domain box: give --udf-box xmin,ymin,zmin,xmax,ymax,zmax or write " + json +
                               " as {\"box\": [[x0,y0,z0],[x1,y1,z1]]}");
  }
  NpyArray values = ReadNpyFloat32(path);
  if (values.shape.size() != 3)
    throw InputError(path, "expected a 3-D array [nx,ny,nz] of distances, got rank " + std::to_string(values.shape.size()));
  const std::array<size_t, 3> dims{values.shape[0], values.shape[1], values.shape[2]};
  std::vector<float> gradient;
  const std::string grad_path = path.substr(0, path.size() - 4) + "_grad.npy";
  if (FileExists(grad_path)) {
    NpyArray g = ReadNpyFloat32(grad_path);
    if (g.shape != std::vector<size_t>{dims[0], dims[1], dims[2], 3})
      throw InputError(grad_path, "expected shape [" + std::to_string(dims[0]) + "," + std::to_string(dims[1]) + "," +
                                      std::to_string(dims[2]) + ",3] to match the distances");
    gradient = std::move(g.data);
  }
  auto udf = std::make_unique<GridUdf>(values.data, dims, box, std::move(gradient), path);
  udf->box_source_ = box_source;
  if (!udf->gradient_.empty()) udf->box_source_ += "; gradients from " + grad_path;
  return udf;
}

void GridUdf::EvaluateChunk(const Vec3* points, size_t count, double* distance, Vec3* gradient) const {
  const bool given = !gradient_.empty();
  const double tiny = 1e-14 * box_.Diagonal();
  const double band = kNormalBand * h_.minCoeff();
  for (size_t n = 0; n < count; ++n) {
    const Vec3& x = points[n];
    if (!x.allFinite()) {
      distance[n] = std::numeric_limits<double>::quiet_NaN();
      gradient[n] = Vec3::Zero();
      continue;
    }
    const Vec3 p = x.cwiseMax(box_.min).cwiseMin(box_.max);
    Stencil s[3];
    for (int k = 0; k < 3; ++k) s[k] = AxisStencil((p[k] - box_.min[k]) / h_[k], dims_[k]);
    // One pass over the 4x4x4 samples: q, grad q and the Hessian of q (used only near the zero set).
    double q = 0.0;
    Vec3 dq = Vec3::Zero();
    double hxx = 0, hyy = 0, hzz = 0, hxy = 0, hxz = 0, hyz = 0;
    Vec3 g_given = Vec3::Zero();
    for (int a = 0; a < 4; ++a) {
      for (int b = 0; b < 4; ++b) {
        const size_t row = (s[0].idx[a] * dims_[1] + s[1].idx[b]) * dims_[2];
        double f = 0.0, fz = 0.0, fzz = 0.0;
        Vec3 gz = Vec3::Zero();
        for (int c = 0; c < 4; ++c) {
          const double v = q_[row + s[2].idx[c]];
          f += s[2].w[c] * v;
          fz += s[2].dw[c] * v;
          fzz += s[2].ddw[c] * v;
          if (given) {
            const float* g = &gradient_[3 * (row + s[2].idx[c])];
            gz += s[2].w[c] * Vec3(g[0], g[1], g[2]);
          }
        }
        const double wa = s[0].w[a], wb = s[1].w[b], da = s[0].dw[a], db = s[1].dw[b];
        q += wa * wb * f;
        dq.x() += da * wb * f;
        dq.y() += wa * db * f;
        dq.z() += wa * wb * fz;
        hxx += s[0].ddw[a] * wb * f;
        hyy += wa * s[1].ddw[b] * f;
        hzz += wa * wb * fzz;
        hxy += da * db * f;
        hxz += da * wb * fz;
        hyz += wa * db * fz;
        if (given) g_given += wa * wb * gz;
      }
    }
    dq = dq.cwiseQuotient(h_);
    const double d_in = std::sqrt(std::max(q, 0.0));
    // In-box part of the gradient of d: grad q / 2d (same direction as grad q), or the given gradient.
    Vec3 g_in = given ? g_given : (d_in > 0.0 ? Vec3(dq / (2.0 * d_in)) : dq);
    if (!given && d_in < band) {
      // Near the zero set grad q = 2 d n + (interpolation error) is dominated by the error and vanishes at
      // the interpolant's minimum; the Hessian of q (about 2 n n^T at a sheet) still knows the normal.
      Eigen::Matrix3d hess;
      hess << hxx / (h_.x() * h_.x()), hxy / (h_.x() * h_.y()), hxz / (h_.x() * h_.z()),
              hxy / (h_.x() * h_.y()), hyy / (h_.y() * h_.y()), hyz / (h_.y() * h_.z()),
              hxz / (h_.x() * h_.z()), hyz / (h_.y() * h_.z()), hzz / (h_.z() * h_.z());
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
      eig.computeDirect(hess);
      Vec3 normal = eig.eigenvectors().col(2);
      if (normal.dot(dq) < 0.0) normal = -normal;
      if (normal.allFinite() && eig.eigenvalues()(2) > 0.0) g_in = normal;
    }
    const Vec3 out = x - p;
    const double out_len = out.norm();
    Vec3 g = g_in;
    if (out_len > 0.0) {
      // Outside the box: d(p) + |x - p|; along the clamped axes the second term is the whole derivative.
      for (int k = 0; k < 3; ++k)
        if (out[k] != 0.0) g[k] = out[k] / out_len;
    }
    distance[n] = d_in + out_len;
    const double len = g.norm();
    gradient[n] = (len > tiny && std::isfinite(len)) ? Vec3(g / len) : Vec3::Zero();
  }
}

std::string GridUdf::Describe() const {
  std::ostringstream out;
  out << name_ << " (grid " << dims_[0] << "x" << dims_[1] << "x" << dims_[2] << ", spacing " << h_.x() << ","
      << h_.y() << "," << h_.z() << "; tricubic Catmull-Rom of d^2; "
      << (gradient_.empty() ? "analytic gradient" : "given gradient") << "; domain " << FormatBox(box_) << " from "
      << box_source_ << ")";
  return out.str();
}

}  // namespace voroudf
