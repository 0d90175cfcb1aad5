// pinmech's compiled core: the user's pin.Model taken by reference from Python (see
// core.hpp for the whole). Boost.Python's converter registry, held by the libboost_python
// that the installed `pin` loads (the cmeel-boost wheel's), finds the C++ Model inside the
// Python object; the layout it assumes is that of the Pinocchio headers this core was
// compiled against, the same version as `pin` (pinned in pyproject.toml, checked at
// import by pinmech/core.py). Alone in its translation unit: Boost.Python's headers stay
// out of the others.
// Pinocchio first: it sets Boost.MPL's limits its joint variant needs
#include <pinocchio/multibody.hpp>

#include <boost/python/extract.hpp>

namespace pinmech {

pinocchio::Model* borrow_model(PyObject* obj) {
  boost::python::extract<pinocchio::Model&> get(obj);
  if (!get.check()) return nullptr;
  return &get();
}

}  // namespace pinmech

namespace pinmech {

pinocchio::Data* borrow_data(PyObject* obj) {
  boost::python::extract<pinocchio::Data&> get(obj);
  if (!get.check()) return nullptr;
  return &get();
}

}  // namespace pinmech
