#pragma once
// The energy of a yarn configuration by kind (J): the rods' stretching, bending and twisting,
// yarn-yarn contact and the contact barrier. The RVE (yarn/rve/rve.hpp) and the strips
// (yarn/strip/strip_problem.hpp) report their energies in it.
namespace yarnhom::yarn {

struct EnergyParts {
  double stretch = 0, bend = 0, twist = 0, contact = 0, barrier = 0;
  double total() const { return stretch + bend + twist + contact + barrier; }
  EnergyParts& operator+=(const EnergyParts& o) {
    stretch += o.stretch, bend += o.bend, twist += o.twist, contact += o.contact, barrier += o.barrier;
    return *this;
  }
};

}  // namespace yarnhom::yarn
