// Pinocchio (C++) timing of the crate's benchmark work; built and run by bench.py.
// argv: a Pinocchio model saved by bench.py (free flyer, mimic joints locked, the four
// end-effector frames added), then the four frame names.
#include <pinocchio/algorithm/center-of-mass.hpp>
#include <pinocchio/algorithm/frames.hpp>
#include <pinocchio/algorithm/jacobian.hpp>
#include <pinocchio/algorithm/joint-configuration.hpp>
#include <pinocchio/serialization.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <vector>

int main(int argc, char** argv) {
  using namespace pinocchio;
  if (argc != 6) return 2;
  Model model;
  model.loadFromBinary(argv[1]);
  std::vector<FrameIndex> frames;
  for (int f = 0; f < 4; ++f) frames.push_back(model.getFrameId(argv[2 + f]));
  Data data(model);
  Eigen::VectorXd q = randomConfiguration(model, model.lowerPositionLimit.cwiseMax(-3.0),
                                          model.upperPositionLimit.cwiseMin(3.0));
  q.segment<4>(3) = Eigen::Vector4d(0.1, -0.2, 0.3, 0.9).normalized();
  std::vector<Data::Matrix6x> jacobians(4, Data::Matrix6x::Zero(6, model.nv));
  const int repetitions = 200000;
  double best = 1e9;
  for (int round = 0; round < 5; ++round) {
    auto start = std::chrono::steady_clock::now();
    for (int i = 0; i < repetitions; ++i) {
      computeJointJacobians(model, data, q);
      updateFramePlacements(model, data);
      jacobianCenterOfMass(model, data, false);
      for (int f = 0; f < 4; ++f) {
        jacobians[f].setZero();
        getFrameJacobian(model, data, frames[f], LOCAL_WORLD_ALIGNED, jacobians[f]);
      }
      asm volatile("" : : "g"(jacobians[3].data()), "g"(data.Jcom.data()) : "memory");
    }
    std::chrono::duration<double> elapsed = std::chrono::steady_clock::now() - start;
    best = std::min(best, elapsed.count() / repetitions);
  }
  std::printf("c++ %.2f us/iteration (nq %d, nv %d)\n", best * 1e6, int(model.nq), int(model.nv));
  return 0;
}
