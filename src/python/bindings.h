#pragma once

// The parts of the hybrid_vo._core module, one file each (module.cc puts them together).

#include <pybind11/pybind11.h>

#include "arguments.h"
#include "hybrid_vo/solvers/minimal_solver.h"

namespace hybrid_vo {
namespace python {

void bind_solvers(py::module_& m);
void bind_estimator(py::module_& m);
void bind_vanishing_points(py::module_& m);
void bind_synthetic(py::module_& m);

// A solver named by function name or paper code ("3-0-1", "2-1-1p", "2-1-1⊥").
SolverId solver_argument(py::handle value, const std::string& name);

}  // namespace python
}  // namespace hybrid_vo
