#include "stages/optimize-seeds/seed_index.h"

#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

namespace voroudf {

struct SeedIndex::Impl {
  pcl::KdTreeFLANN<pcl::PointXYZ> tree{/*sorted=*/true};
};

SeedIndex::SeedIndex(const std::vector<Vec3>& points) : impl_(std::make_unique<Impl>()) {
  auto cloud = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  cloud->resize(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    (*cloud)[i] = pcl::PointXYZ(static_cast<float>(points[i].x()), static_cast<float>(points[i].y()),
                                static_cast<float>(points[i].z()));
  }
  impl_->tree.setInputCloud(cloud);
}

SeedIndex::~SeedIndex() = default;

namespace {
pcl::PointXYZ ToPcl(const Vec3& p) {
  return pcl::PointXYZ(static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z()));
}
}  // namespace

void SeedIndex::Nearest(const Vec3& query, int k, std::vector<int>& indices) const {
  std::vector<float> squared;
  indices.clear();
  const int n = static_cast<int>(impl_->tree.getInputCloud()->size());
  if (k > n) k = n;
  if (k <= 0) return;
  impl_->tree.nearestKSearch(ToPcl(query), k, indices, squared);
}

void SeedIndex::WithinRadius(const Vec3& query, double radius, std::vector<int>& indices) const {
  std::vector<float> squared;
  indices.clear();
  impl_->tree.radiusSearch(ToPcl(query), radius, indices, squared);
}

}  // namespace voroudf
