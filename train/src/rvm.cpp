#include "rvm.h"

#include <dlib/svm.h>

namespace pdvo::internal {
namespace {

using Sample = dlib::matrix<double, 0, 1>;
using Kernel = dlib::radial_basis_kernel<Sample>;

std::vector<Sample> ToSamples(const Eigen::MatrixXd& x) {
  std::vector<Sample> samples(x.rows());
  for (Eigen::Index i = 0; i < x.rows(); ++i) {
    samples[i].set_size(x.cols());
    for (Eigen::Index j = 0; j < x.cols(); ++j) samples[i](j) = x(i, j);
  }
  return samples;
}

RvmFunction FromDlib(const dlib::decision_function<Kernel>& f, double gamma) {
  RvmFunction out;
  out.gamma = gamma;
  out.bias = f.b;
  const long n = f.basis_vectors.size();
  out.weights.resize(n);
  out.vectors.resize(n, n > 0 ? f.basis_vectors(0).size() : 0);
  for (long i = 0; i < n; ++i) {
    out.weights[i] = f.alpha(i);
    for (long j = 0; j < f.basis_vectors(i).size(); ++j) out.vectors(i, j) = f.basis_vectors(i)(j);
  }
  return out;
}

}  // namespace

RvmFunction TrainRvmClassifier(const Eigen::MatrixXd& x, const std::vector<double>& labels, double gamma,
                               double epsilon, int max_iterations) {
  dlib::rvm_trainer<Kernel> trainer;
  trainer.set_kernel(Kernel(gamma));
  trainer.set_epsilon(epsilon);
  trainer.set_max_iterations(max_iterations);
  return FromDlib(trainer.train(ToSamples(x), labels), gamma);
}

}  // namespace pdvo::internal
