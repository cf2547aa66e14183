// What both sides of the benchmark read: the arm (as written by bench/run.py, in plain numbers,
// so the Pinocchio side is built without going through dynid) and the precomputed states.
#pragma once

#include <Eigen/Core>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace bench {

// Whitespace-separated, one keyword per line ('#' starts a comment):
//   convention standard|modified
//   gravity gx gy gz                        (world frame)
//   base r00 r01 r02 r03 ... r33            (16 numbers, row-major: world <- frame 0)
//   joint R|P a alpha d theta               (one line per link, in order; docs/conventions.md)
//   params m mx my mz Ixx Ixy Ixz Iyy Iyz Izz   (one line per link, about DH frame i)
//   Ia / Fv / Fs  n numbers each            (optional, zeros when absent)
struct ModelFile {
  struct Joint {
    bool revolute = true;
    double a = 0.0, alpha = 0.0, d = 0.0, theta = 0.0;
  };
  bool standard = true;
  Eigen::Vector3d gravity{0.0, 0.0, -9.81};
  Eigen::Matrix4d base = Eigen::Matrix4d::Identity();
  std::vector<Joint> joints;
  std::vector<Eigen::Matrix<double, 10, 1>> params;
  Eigen::VectorXd Ia, Fv, Fs;

  int n() const { return static_cast<int>(joints.size()); }
};

inline std::vector<double> read_numbers(std::istringstream& line) {
  std::vector<double> values;
  double x;
  while (line >> x) values.push_back(x);
  return values;
}

inline Eigen::VectorXd read_drive(std::istringstream& line) {
  const std::vector<double> v = read_numbers(line);
  return Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
}

inline ModelFile read_model(const std::string& path) {
  std::ifstream file(path);
  if (!file) throw std::runtime_error("cannot open model file " + path);
  ModelFile model;
  std::string text;
  while (std::getline(file, text)) {
    std::istringstream line(text);
    std::string key;
    if (!(line >> key) || key[0] == '#') continue;
    if (key == "convention") {
      std::string value;
      line >> value;
      if (value != "standard" && value != "modified")
        throw std::runtime_error("convention: expected standard or modified, got " + value);
      model.standard = value == "standard";
    } else if (key == "gravity") {
      const std::vector<double> g = read_numbers(line);
      if (g.size() != 3) throw std::runtime_error("gravity: expected 3 numbers");
      model.gravity = Eigen::Vector3d(g[0], g[1], g[2]);
    } else if (key == "base") {
      const std::vector<double> b = read_numbers(line);
      if (b.size() != 16) throw std::runtime_error("base: expected 16 numbers");
      for (int k = 0; k < 16; ++k) model.base(k / 4, k % 4) = b[k];
    } else if (key == "joint") {
      std::string type;
      line >> type;
      const std::vector<double> v = read_numbers(line);
      if ((type != "R" && type != "P") || v.size() != 4)
        throw std::runtime_error("joint: expected R or P and 4 numbers a alpha d theta");
      model.joints.push_back({type == "R", v[0], v[1], v[2], v[3]});
    } else if (key == "params") {
      const std::vector<double> p = read_numbers(line);
      if (p.size() != 10) throw std::runtime_error("params: expected 10 numbers");
      model.params.emplace_back(Eigen::Map<const Eigen::Matrix<double, 10, 1>>(p.data()));
    } else if (key == "Ia") {
      model.Ia = read_drive(line);
    } else if (key == "Fv") {
      model.Fv = read_drive(line);
    } else if (key == "Fs") {
      model.Fs = read_drive(line);
    } else {
      throw std::runtime_error("model file: unknown keyword " + key);
    }
  }
  const int n = model.n();
  if (n == 0) throw std::runtime_error("model file: no joint lines");
  if (static_cast<int>(model.params.size()) != n)
    throw std::runtime_error("model file: expected one params line per joint");
  for (Eigen::VectorXd* drive : {&model.Ia, &model.Fv, &model.Fs}) {
    if (drive->size() == 0) *drive = Eigen::VectorXd::Zero(n);
    if (drive->size() != n) throw std::runtime_error("model file: Ia, Fv, Fs need one number per joint");
  }
  return model;
}

// Column k of each matrix is state k; tau = rnea(q, qd, qdd), so that forward dynamics on
// (q, qd, tau) has a known answer.
struct States {
  Eigen::MatrixXd q, qd, qdd, tau;
};

}  // namespace bench
