#pragma once

// The parts of the hybrid_vo._core module, one file each (module.cc puts them together).

#include <pybind11/pybind11.h>

#include "options.h"

namespace hybrid_vo::python {

void bind_solvers(py::module_& m);
void bind_estimator(py::module_& m);
void bind_vanishing_points(py::module_& m);
void bind_synthetic(py::module_& m);

}  // namespace hybrid_vo::python
