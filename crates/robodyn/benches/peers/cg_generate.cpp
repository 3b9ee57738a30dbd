// Pinocchio + CppADCodeGen: writes the C sources of the generated rnea, crba, aba, rnea
// derivatives and CppAD's Jacobian of rnea of a model
// (driven by codegen.py; NOT run by CI).
//
//   cg_generate MODEL OUTDIR
//
// Pinocchio's own code generators (CodeGenRNEA, CodeGenCRBA, CodeGenABA, CodeGenRNEADerivatives of
// pinocchio/codegen/cppadcg-algo.hpp: the algorithm traced on CppAD::AD<CG<double>>, the tape
// optimized, the C source emitted by CppADCodeGen) with the zero-order forward function only
// (no Jacobian). The functions are named `<name>_forward_zero(in, out, atomics)` with
// in[0] = x (rnea: [q v a], crba: q, aba: [q v tau]) and out[0] = y (rnea: tau, crba: the upper
// triangle of M row by row, aba: ddq; drnea: [q v a] -> [dtau_dq, dtau_dv, dtau_da], each
// nv x nv row-major, computeRNEADerivatives traced; Pinocchio's generators run crba and aba in
// the WORLD convention). jrnea is CppAD's Jacobian of rnea, as Pinocchio's
// `CodeGenRNEA::evalJacobian` (its benchmark's "RNEA partial derivatives code gen"): the function
// `jrnea_jacobian(in, out, atomics)`, out[0] = d tau / d[q v a], nv x (nq + 2 nv) row-major, by
// CppAD's dense Jacobian driver (`JacobianADMode::Automatic`, the generator's default). codegen.py compiles them with the same flags as robodyn's generated C.

#include <pinocchio/codegen/cppadcg-algo.hpp>

#include "peer_model.hpp"

#include <fstream>
#include <iostream>
#include <string>

// ModelCSourceGen::getSources is protected, and ModelLibraryCSourceGen::saveSources does not compile
// in this CppADCodeGen (it calls getSources() without its two arguments): a pointer to the member,
// formed in a derived class, reads the sources.
struct SourcesAccess : CppAD::cg::ModelCSourceGen<double> {
  static auto get() { return &SourcesAccess::getSources; }
};

template <class Gen>
static void emit(Gen& gen, const std::string& dir, bool jacobian = false) {
  gen.initLib();
  CppAD::cg::ModelCSourceGen<double>& src = gen.codeGenerator();
  src.setCreateJacobian(jacobian);
  src.setCreateForwardZero(!jacobian);
  const auto& sources = (src.*SourcesAccess::get())(CppAD::cg::MultiThreadingType::NONE, nullptr);
  for (const auto& [name, code] : sources) {
    std::ofstream out(dir + "/" + name);
    out << code;
    if (!out) throw std::runtime_error("cannot write " + dir + "/" + name);
  }
}

int main(int argc, char** argv) {
  if (argc != 3) {
    std::cerr << "usage: cg_generate MODEL OUTDIR\n";
    return 2;
  }
  const pinocchio::Model model = read_model(argv[1]);
  const std::string dir = argv[2];
  {
    pinocchio::CodeGenRNEA<double> gen(model, "rnea");
    emit(gen, dir);
  }
  {
    pinocchio::CodeGenCRBA<double> gen(model, "crba");
    emit(gen, dir);
  }
  {
    pinocchio::CodeGenABA<double> gen(model, "aba");
    emit(gen, dir);
  }
  {
    // computeRNEADerivatives traced: out = [dtau_dq, dtau_dv, dtau_da], each row-major
    pinocchio::CodeGenRNEADerivatives<double> gen(model, "drnea");
    emit(gen, dir);
  }
  {
    // CppAD's Jacobian of rnea: out = d tau / d[q v a], nv x 3 nv row-major (nq = nv here)
    pinocchio::CodeGenRNEA<double> gen(model, "jrnea");
    emit(gen, dir, true);
  }
  return 0;
}
