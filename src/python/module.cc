// hybrid_vo._core: the core library (solvers, estimator, VP detection, synthetic data) for
// Python, one file a part. python/hybrid_vo/__init__.py re-exports it as the package hybrid_vo.
#include <pybind11/pybind11.h>

namespace hybrid_vo::python {
void bind_solvers(pybind11::module_& m);
void bind_estimator(pybind11::module_& m);
void bind_vanishing_points(pybind11::module_& m);
void bind_synthetic(pybind11::module_& m);
}  // namespace hybrid_vo::python

PYBIND11_MODULE(_core, m) {
  namespace python = hybrid_vo::python;
  // Docstrings carry their own "name(args)\n--\n\n" signature line, which CPython turns into
  // __text_signature__ (inspect.signature, help) with the real defaults.
  pybind11::options options;
  options.disable_function_signatures();
  m.doc() = "hybrid_vo core bindings; use the package hybrid_vo.";
  python::bind_solvers(m);
  python::bind_estimator(m);
  python::bind_vanishing_points(m);
  python::bind_synthetic(m);
}
