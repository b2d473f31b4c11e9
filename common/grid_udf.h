#pragma once
// `--udf path.npy`: a UDF sampled on a regular grid, as learned UDFs (NDF, CAP-UDF, GeoUDF) are usually
// exported (docs/udf-sources.md, "Grid").
#include <array>
#include <memory>
#include <string>
#include <vector>

#include "common/udf.h"

namespace voroudf {

/// A float32 array read from a NumPy .npy file.
struct NpyArray {
  std::vector<size_t> shape;
  std::vector<float> data;  ///< C (row-major) order
};

/// Reads a .npy file (format versions 1, 2, 3; NumPy's NEP 1). Accepts only little-endian float32
/// ('<f4') in C order; anything else (another dtype, Fortran order, a truncated file) is an InputError
/// that says what was found and what to do.
NpyArray ReadNpyFloat32(const std::string& path);
/// The same from a whole .npy file's bytes in memory; `name` names it in messages.
NpyArray ParseNpyFloat32(const std::string& bytes, const std::string& name);

/// Writes a little-endian float32 C-order .npy (version 1.0) atomically. Throws OutputError.
void WriteNpyFloat32(const std::string& path, const std::vector<size_t>& shape, const std::vector<float>& data);

/// Parses "x0,y0,z0,x1,y1,z1" (the --udf-box option). Throws UsageError unless six finite numbers with
/// x0 < x1, y0 < y1, z0 < z1.
Box ParseBoxOption(const std::string& text);

/// Reads a sidecar `{"box": [[x0,y0,z0],[x1,y1,z1]]}` (other keys are ignored). Throws InputError.
Box ReadBoxJson(const std::string& path);
/// The same from the sidecar's text; `path` names it in messages.
Box ParseBoxJson(const std::string& text, const std::string& path);

/// A UDF sampled at the nodes of a regular grid:
/// value[i][j][k] (C order, k fastest) is d at box.min + (i, j, k) * box.Extent() / (n - 1), so the first
/// and last samples of each axis lie on the box faces and i runs along x, j along y, k along z.
///
/// Interpolation: tricubic Catmull-Rom (Keys' cubic convolution, a = -1/2; C1, interpolating, exact for
/// quadratics) of the squared samples q = max(d, 0)^2, and d = sqrt(max(q, 0)). Interpolating d^2 rather than
/// d matters at the zero set: d^2 is smooth across a sheet, so the interpolant still comes close to zero on
/// the surface (1.2e-3 = 0.065 h on a 64^3 sphere), while a cubic of d rounds the kink |s| off to a minimum of
/// up to 0.375 h and trilinear to up to h/2 (the 1-D values for a sheet midway between two nodes).
/// Gradient: the analytic gradient of the interpolant, normalised (grad d = grad q / 2d has the same
/// direction), so it is consistent with the values. Within kNormalBand = h/4 of the zero set, where grad q
/// is dominated by the interpolation error and vanishes at the interpolant's minimum, it is the principal
/// eigenvector of the Hessian of q (about 2 n n^T at a sheet) oriented along grad q. The zero vector where
/// neither can tell. With a gradient array it is that array interpolated with the same weights, normalised.
/// Measured on the 64^3 sphere (tests/test_grid_udf.cpp): |d error| <= 2.9e-5 farther than 2h from the
/// surface and the centre, <= 1.3e-3 nearer; gradient angle <= 7.5e-3 rad far, <= 3.9e-2 rad near.
/// Ghost nodes beyond the faces are extrapolated quadratically (f(-1) = 3 f0 - 3 f1 + f2), keeping the
/// third order up to the faces.
/// Samples outside the grid use ghost nodes by linear extrapolation; queries outside the box get
/// d(clamp(x)) + |x - clamp(x)| and that function's gradient.
class GridUdf : public Udf {
 public:
  /// \param values   nx*ny*nz samples of d in C order (negative values count as 0)
  /// \param dims     {nx, ny, nz}, each >= 2
  /// \param box      the grid's box (min < max on every axis)
  /// \param gradient optional, 3*nx*ny*nz values in C order (component fastest), or empty
  /// Throws InputError for inconsistent sizes or non-finite samples.
  GridUdf(const std::vector<float>& values, std::array<size_t, 3> dims, const Box& box,
          std::vector<float> gradient, std::string name);

  /// Opens `path.npy` ([nx,ny,nz] float32). The box comes from `box_option` (--udf-box) when it is not
  /// empty, else from the sidecar `path.json` (the .npy extension replaced). A gradient array
  /// `path_grad.npy` ([nx,ny,nz,3] float32) beside it is used when it exists. Throws InputError
  /// (missing file or box, wrong dtype or rank), UsageError (malformed --udf-box).
  static std::unique_ptr<GridUdf> Open(const std::string& path, const std::string& box_option);

  void EvaluateChunk(const Vec3* points, size_t count, double* distance, Vec3* gradient) const override;
  Box Domain() const override { return box_; }
  std::string Describe() const override;

  std::array<size_t, 3> dims() const { return dims_; }
  Vec3 spacing() const { return h_; }

 private:
  double Sample(size_t i, size_t j, size_t k) const { return q_[(i * dims_[1] + j) * dims_[2] + k]; }

  std::vector<float> q_;         // squared distances
  std::vector<float> gradient_;  // optional, 3 per node
  std::array<size_t, 3> dims_;
  Box box_;
  Vec3 h_;
  std::string name_;
  std::string box_source_;
};

}  // namespace voroudf
