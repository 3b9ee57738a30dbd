// Pinocchio side of the side-by-side benchmark (driven by run.py; NOT run by CI).
//
// Header-only Pinocchio (pip wheel headers), built with -O3 -march=native. The model is NOT parsed
// from the URDF here: Pinocchio's URDF parser needs urdfdom, a shared library of the wheel built
// without -march=native, and mixing the two crashes. run.py parses the URDF with the wheel's
// Python bindings (the same parser, which merges fixed joints into their parent body) and dumps
// every joint (parent, type, axis, placement, inertia); this program rebuilds the identical model
// with Model::addJoint / appendBodyToJoint.
//
//   pinocchio_peer MODEL STATES RESULTS [--samples N] [--target-us T]
//
// A model whose first joint is a free flyer (run.py's floating robots) has states with q over
// nq = 7 + n; only the dynamics (rnea, crba, aba, composite) are then written and timed.
//
// Writes the results of every algorithm on every state to RESULTS (for the agreement check) and
// prints `time <algorithm> <median ns per call>` lines: each sample times a loop over all states,
// repeated so that a sample lasts about T microseconds; the median over the samples is printed.

#include "peer_model.hpp"

#include <pinocchio/algorithm/aba.hpp>
#include <pinocchio/algorithm/aba-derivatives.hpp>
#include <pinocchio/algorithm/center-of-mass.hpp>
#include <pinocchio/algorithm/frames.hpp>
#include <pinocchio/algorithm/jacobian.hpp>
#include <pinocchio/algorithm/cholesky.hpp>
#include <pinocchio/algorithm/crba.hpp>
#include <pinocchio/algorithm/rnea.hpp>
#include <pinocchio/algorithm/rnea-derivatives.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

using pinocchio::Convention;
using Model = pinocchio::Model;
using Data = pinocchio::Data;
using VectorXd = Eigen::VectorXd;

struct State {
  VectorXd q, v, a, tau;
};

// q has nq entries (7 + n with a free-flyer root: position, quaternion x y z w), v, a, tau nv.
static std::vector<State> read_states(const std::string& path, int nq, int nv) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read " + path);
  std::string line;
  std::getline(in, line);  // names
  std::vector<State> states;
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    std::istringstream s(line);
    State st{VectorXd(nq), VectorXd(nv), VectorXd(nv), VectorXd(nv)};
    for (VectorXd* x : {&st.q, &st.v, &st.a, &st.tau})
      for (int k = 0; k < x->size(); ++k) s >> (*x)[k];
    if (!s) throw std::runtime_error("bad state line");
    states.push_back(st);
  }
  return states;
}

static void fill_lower(Data& data) {
  data.M.triangularView<Eigen::StrictlyLower>() =
      data.M.transpose().triangularView<Eigen::StrictlyLower>();
}

// qdd = A^-1 (tau - H): crba, nonLinearEffects (rnea with a = 0), Cholesky (Pinocchio's sparse
// tree factorization) and solve.
static void composite(const Model& model, Data& data, const State& s, Convention c, VectorXd& x) {
  pinocchio::crba(model, data, s.q, c);
  pinocchio::nonLinearEffects(model, data, s.q, s.v);
  pinocchio::cholesky::decompose(model, data);
  x = s.tau - data.nle;
  pinocchio::cholesky::solve(model, data, x);
}

int main(int argc, char** argv) {
  if (argc < 4) {
    std::cerr << "usage: pinocchio_peer MODEL STATES RESULTS [--samples N] [--target-us T]\n";
    return 2;
  }
  int samples = 21;
  double target_us = 400.0;
  for (int k = 4; k + 1 < argc; k += 2) {
    std::string o = argv[k];
    if (o == "--samples") samples = std::atoi(argv[k + 1]);
    else if (o == "--target-us") target_us = std::atof(argv[k + 1]);
  }
  Model built = read_model(argv[1]);
  // the kinematics' frame: the last joint's own frame (robodyn's frame of that URDF joint)
  const pinocchio::JointIndex last = built.njoints - 1;
  const pinocchio::FrameIndex tip = built.addJointFrame(last, -1);
  const Model model = built;
  Data data(model);
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(6, model.nv);
  const int nv = model.nv;
  const std::vector<State> states = read_states(argv[2], model.nq, nv);
  // a free-flyer root (nq = nv + 1): the dynamics only (rnea, crba, aba, composite)
  const bool floating = model.nq != model.nv;
  VectorXd x(nv);

  {
    std::ofstream out(argv[3]);
    out.precision(17);
    for (const State& s : states) {
      out << "rnea";
      pinocchio::rnea(model, data, s.q, s.v, s.a);
      for (int k = 0; k < nv; ++k) out << ' ' << data.tau[k];
      out << "\ncrba";
      data.M.setZero();
      pinocchio::crba(model, data, s.q, Convention::LOCAL);
      // whether crba writes below the diagonal (printed once; M was zeroed before)
      if (&s == &states[0])
        std::printf("crba_fills %s\n",
                    data.M.triangularView<Eigen::StrictlyLower>().toDenseMatrix().isZero(0)
                        ? "upper" : "both");
      fill_lower(data);
      for (int r = 0; r < nv; ++r)
        for (int c = 0; c < nv; ++c) out << ' ' << data.M(r, c);
      out << "\naba";
      pinocchio::aba(model, data, s.q, s.v, s.tau, Convention::LOCAL);
      for (int k = 0; k < nv; ++k) out << ' ' << data.ddq[k];
      out << "\ncomposite";
      composite(model, data, s, Convention::LOCAL, x);
      for (int k = 0; k < nv; ++k) out << ' ' << x[k];
      if (floating) {
        out << '\n';
        continue;
      }
      out << "\njac";
      J.setZero();
      pinocchio::computeFrameJacobian(model, data, s.q, tip, pinocchio::LOCAL, J);
      for (int r = 0; r < 6; ++r)
        for (int c = 0; c < nv; ++c) out << ' ' << J(r, c);
      out << "\ncom";
      pinocchio::jacobianCenterOfMass(model, data, s.q);
      for (int r = 0; r < 3; ++r) out << ' ' << data.com[0][r];
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < nv; ++c) out << ' ' << data.Jcom(r, c);
      // derivatives (issue 28): dtau/dq then dtau/dv; ddq/dq then ddq/dv
      out << "\ndrnea";
      pinocchio::computeRNEADerivatives(model, data, s.q, s.v, s.a);
      for (const auto* m : {&data.dtau_dq, &data.dtau_dv})
        for (int r = 0; r < nv; ++r)
          for (int c = 0; c < nv; ++c) out << ' ' << (*m)(r, c);
      out << "\ndaba";
      pinocchio::computeABADerivatives(model, data, s.q, s.v, s.tau);
      for (const auto* m : {&data.ddq_dq, &data.ddq_dv})
        for (int r = 0; r < nv; ++r)
          for (int c = 0; c < nv; ++c) out << ' ' << (*m)(r, c);
      out << '\n';
    }
  }

  double sink = 0.0;
  auto time = [&](const char* name, const std::function<void(const State&)>& f) {
    using clock = std::chrono::steady_clock;
    auto pass = [&] {
      for (const State& s : states) f(s);
    };
    pass();
    auto t0 = clock::now();
    pass();
    double one = std::chrono::duration<double, std::micro>(clock::now() - t0).count();
    int reps = std::max(1, int(target_us / std::max(one, 1e-3)));
    std::vector<double> ns;
    for (int k = 0; k < samples; ++k) {
      auto a = clock::now();
      for (int r = 0; r < reps; ++r) pass();
      double el = std::chrono::duration<double, std::nano>(clock::now() - a).count();
      ns.push_back(el / double(reps * states.size()));
    }
    std::nth_element(ns.begin(), ns.begin() + ns.size() / 2, ns.end());
    std::printf("time %s %.1f\n", name, ns[ns.size() / 2]);
  };

  time("rnea", [&](const State& s) { sink += pinocchio::rnea(model, data, s.q, s.v, s.a)[0]; });
  for (Convention c : {Convention::LOCAL, Convention::WORLD}) {
    const char* suffix = c == Convention::LOCAL ? "local" : "world";
    std::string n1 = std::string("crba_upper_") + suffix;
    std::string n2 = std::string("crba_full_") + suffix;
    std::string n3 = std::string("aba_") + suffix;
    std::string n4 = std::string("composite_") + suffix;
    time(n1.c_str(), [&](const State& s) { sink += pinocchio::crba(model, data, s.q, c)(0, 0); });
    time(n2.c_str(), [&](const State& s) {
      pinocchio::crba(model, data, s.q, c);
      fill_lower(data);
      sink += data.M(nv - 1, 0);
    });
    time(n3.c_str(), [&](const State& s) {
      sink += pinocchio::aba(model, data, s.q, s.v, s.tau, c)[0];
    });
    time(n4.c_str(), [&](const State& s) {
      composite(model, data, s, c, x);
      sink += x[0];
    });
  }
  if (floating) {
    std::fprintf(stderr, "sink %g\n", sink);
    return 0;
  }
  // kinematics (issue 26): from q each time, as a controller calls them
  time("joint_jacobians", [&](const State& s) {
    sink += pinocchio::computeJointJacobians(model, data, s.q)(0, nv - 1);
  });
  time("all_frame_jacobians", [&](const State& s) {
    pinocchio::computeJointJacobians(model, data, s.q);
    for (pinocchio::JointIndex j = 1; j < (pinocchio::JointIndex)model.njoints; ++j) {
      J.setZero();
      pinocchio::getJointJacobian(model, data, j, pinocchio::WORLD, J);
      sink += J(0, 0);
    }
  });
  time("frame_jacobian", [&](const State& s) {
    J.setZero();
    pinocchio::computeFrameJacobian(model, data, s.q, tip, pinocchio::LOCAL, J);
    sink += J(0, 0);
  });
  time("com_jacobian", [&](const State& s) {
    sink += pinocchio::jacobianCenterOfMass(model, data, s.q)(0, 0) + data.com[0][0];
  });
  time("rnea_derivatives", [&](const State& s) {
    pinocchio::computeRNEADerivatives(model, data, s.q, s.v, s.a);
    sink += data.dtau_dq(0, 0);
  });
  time("aba_derivatives", [&](const State& s) {
    pinocchio::computeABADerivatives(model, data, s.q, s.v, s.tau);
    sink += data.ddq_dq(0, 0);
  });
  std::fprintf(stderr, "sink %g\n", sink);
  return 0;
}
