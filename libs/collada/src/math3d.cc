#include "math3d.h"

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <cmath>

namespace caliper::collada::internal {

namespace {
constexpr double kPi = 3.14159265358979323846;
}

Eigen::Matrix3d AxisAngleDegrees(const Eigen::Vector3d& axis, double degrees) {
  const double n = axis.norm();
  if (!(n > 0) || !std::isfinite(n)) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(degrees * kPi / 180.0, axis / n).toRotationMatrix();
}

std::pair<Eigen::Vector3d, double> ToAxisAngleDegrees(const Eigen::Quaterniond& q) {
  const Eigen::AngleAxisd aa(q.normalized());
  if (std::abs(aa.angle()) < 1e-300) return {Eigen::Vector3d::UnitX(), 0.0};
  return {aa.axis(), aa.angle() * 180.0 / kPi};
}

void SplitRigid(const Eigen::Affine3d& m, Eigen::Isometry3d* rigid, Eigen::Matrix3d* residual) {
  const Eigen::Matrix3d l = m.linear();
  Eigen::Matrix3d r;
  if ((l - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() < 1e-12) {
    r = Eigen::Matrix3d::Identity();
  } else {
    // polar decomposition l = r s with r the nearest rotation
    Eigen::JacobiSVD<Eigen::Matrix3d> svd(l, Eigen::ComputeFullU | Eigen::ComputeFullV);
    Eigen::Matrix3d u = svd.matrixU();
    const Eigen::Matrix3d v = svd.matrixV();
    if ((u * v.transpose()).determinant() < 0) u.col(2) = -u.col(2);
    r = u * v.transpose();
  }
  *rigid = Eigen::Isometry3d::Identity();
  rigid->linear() = r;
  rigid->translation() = m.translation();
  *residual = r.transpose() * l;
}

sgal::Pose RigidPose(const Eigen::Affine3d& m) {
  Eigen::Isometry3d rigid;
  Eigen::Matrix3d residual;
  SplitRigid(m, &rigid, &residual);
  return sgal::Pose::FromIsometry(rigid);
}

bool NearIdentity(const Eigen::Matrix3d& m, double tolerance) {
  return (m - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() <= tolerance;
}

Eigen::Quaterniond RotationZTo(const Eigen::Vector3d& axis) {
  const double n = axis.norm();
  if (!(n > 0)) return Eigen::Quaterniond::Identity();
  return Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), axis / n);
}

void PrincipalAxes(const Eigen::Matrix3d& tensor, Eigen::Vector3d* moments, Eigen::Matrix3d* axes) {
  const Eigen::Matrix3d sym = 0.5 * (tensor + tensor.transpose());
  // a diagonal tensor keeps its axes (and the order of its moments)
  const Eigen::Matrix3d off = sym - Eigen::Matrix3d(sym.diagonal().asDiagonal());
  if (off.cwiseAbs().maxCoeff() <= 1e-15 * (1 + sym.cwiseAbs().maxCoeff())) {
    *moments = sym.diagonal();
    *axes = Eigen::Matrix3d::Identity();
    return;
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(sym);
  *moments = eig.eigenvalues();
  *axes = eig.eigenvectors();
  if (axes->determinant() < 0) axes->col(2) = -axes->col(2);
}

}  // namespace caliper::collada::internal
