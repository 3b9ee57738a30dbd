// The model file written by run.py (one line per joint, see dump_model there) -> pinocchio::Model.
// Shared by pinocchio_peer.cpp and cg_generate.cpp.
#pragma once

#include <pinocchio/multibody.hpp>

#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

inline pinocchio::Model read_model(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read " + path);
  pinocchio::Model model;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream s(line);
    std::string tag, name, type;
    s >> tag;
    if (tag == "gravity") {
      s >> model.gravity.linear()[0] >> model.gravity.linear()[1] >> model.gravity.linear()[2];
      continue;
    }
    if (tag != "joint") throw std::runtime_error("unknown line: " + line);
    int parent;
    double ax[3], r[9], p[3], m, c[3], in6[6];
    s >> name >> parent >> type;
    for (double& x : ax) s >> x;
    for (double& x : r) s >> x;
    for (double& x : p) s >> x;
    s >> m;
    for (double& x : c) s >> x;
    for (double& x : in6) s >> x;
    if (!s) throw std::runtime_error("bad joint line: " + line);
    Eigen::Matrix3d rot;
    rot << r[0], r[1], r[2], r[3], r[4], r[5], r[6], r[7], r[8];
    const pinocchio::SE3 placement(rot, Eigen::Vector3d(p[0], p[1], p[2]));
    const Eigen::Vector3d axis(ax[0], ax[1], ax[2]);
    pinocchio::JointIndex id;
    if (type == "RX") id = model.addJoint(parent, pinocchio::JointModelRX(), placement, name);
    else if (type == "RY") id = model.addJoint(parent, pinocchio::JointModelRY(), placement, name);
    else if (type == "RZ") id = model.addJoint(parent, pinocchio::JointModelRZ(), placement, name);
    else if (type == "PX") id = model.addJoint(parent, pinocchio::JointModelPX(), placement, name);
    else if (type == "PY") id = model.addJoint(parent, pinocchio::JointModelPY(), placement, name);
    else if (type == "PZ") id = model.addJoint(parent, pinocchio::JointModelPZ(), placement, name);
    else if (type == "FF") id = model.addJoint(parent, pinocchio::JointModelFreeFlyer(), placement, name);
    else if (type == "RU")
      id = model.addJoint(parent, pinocchio::JointModelRevoluteUnaligned(axis), placement, name);
    else if (type == "PU")
      id = model.addJoint(parent, pinocchio::JointModelPrismaticUnaligned(axis), placement, name);
    else throw std::runtime_error("joint type not handled: " + type);
    Eigen::Matrix3d inertia;
    inertia << in6[0], in6[1], in6[2], in6[1], in6[3], in6[4], in6[2], in6[4], in6[5];
    model.appendBodyToJoint(id, pinocchio::Inertia(m, Eigen::Vector3d(c[0], c[1], c[2]), inertia),
                            pinocchio::SE3::Identity());
  }
  return model;
}
