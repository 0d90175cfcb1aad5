// pinmech's compiled core: the Python bindings, pinmech._core (see core.hpp for the whole
// and pinmech/core.py for its Python face).
#include "core.hpp"

#include <pinocchio/config.hpp>

#include <boost/version.hpp>

#include <Eigen/LU>

#include <stdexcept>

using namespace pinmech;

NB_MODULE(_core, m) {
  m.doc() = "pinmech's compiled core: sweeps of closed-loop mechanisms on Pinocchio (see pinmech/core.py)";
  m.attr("DEFAULT_TOL") = DEFAULT_TOL;
  m.attr("POLISH") = POLISH;
  m.attr("MAX_NEWTON_STEP") = MAX_NEWTON_STEP;
  m.attr("MAX_STEP") = MAX_STEP;
  m.attr("TRUST") = TRUST;
  m.attr("MAX_TURN") = MAX_TURN;
  m.attr("PIVOT_BELOW") = PIVOT_BELOW;
  m.attr("CORRECTOR_ITERATIONS") = CORRECTOR_ITERATIONS;
  m.attr("SINGULAR_NODE") = SINGULAR_NODE;
  m.attr("BIFURCATION_STEP") = BIFURCATION_STEP;
  m.attr("FOLD_TOL") = FOLD_TOL;
  m.attr("LAND_TOL") = LAND_TOL;
  m.attr("MAX_PIVOT_STEPS") = MAX_PIVOT_STEPS;
  // What the core was compiled against: pinmech/core.py refuses a pin that differs.
  m.attr("PINOCCHIO_VERSION") = PINOCCHIO_VERSION;
  m.attr("BOOST_VERSION") = BOOST_VERSION;
  m.def(
      "condition",
      [](const MatrixXd& A) {
        if (A.rows() != A.cols()) throw std::invalid_argument("condition: A must be square");
        ConditionWork work;
        const Eigen::PartialPivLU<MatrixXd> lu(A);
        return condition_of(A, A.rows() > 0 && lu.matrixLU().diagonal().cwiseAbs().minCoeff() == 0.0, work);
      },
      "2-norm condition number and smallest singular value of a square A, as the core computes them");
  m.def(
      "conditions",
      [](const std::vector<MatrixXd>& As, Eigen::Index lower, Eigen::Index upper) {
        ConditionWork work;  // one for the sequence: each search starts from the last matrix's values
        const Band band{lower, upper};
        std::vector<std::pair<double, double>> out;
        for (const MatrixXd& A : As) {
          if (A.rows() != A.cols()) throw std::invalid_argument("conditions: every A must be square");
          const Eigen::PartialPivLU<MatrixXd> lu(A);
          const bool singular = A.rows() > 0 && lu.matrixLU().diagonal().cwiseAbs().minCoeff() == 0.0;
          out.push_back(condition_of(A, singular, work, lower >= 0 && upper >= 0 ? &band : nullptr));
        }
        return out;
      },
      nb::arg("As"), nb::arg("lower") = -1, nb::arg("upper") = -1,
      "condition for each A in turn, as along a path (each search warm-started from the last A's values); "
      "lower, upper: the structural band (every entry beyond it exactly zero), else found by a scan");
  m.attr("KINEMATICS_COLUMNS") = KINEMATICS_COLUMNS;
  m.attr("RATE_NUMBERS") = RATE_NUMBERS;
  m.attr("CERTIFY_EVERY_POSE") = CERTIFY_EVERY_POSE;
  m.attr("CERTIFY_ENDS") = CERTIFY_ENDS;
  m.attr("CERTIFY_NONE") = CERTIFY_NONE;
  m.def("frames_at", &frames_at,
        "frames_at(model, data, q, v, a, frames, joints, out): forwardKinematics(q, v, a) in the user's data, "
        "then a row per frame and joint asked into out (kinematics.cpp)");
  m.def("frames_along", &frames_along,
        "frames_along(model, data, Q, V, A, frames, out): frames_at at every row, into out (N, frames * 24)");
  m.def("cut_rows_change", &cut_rows_change,
        "cut_rows_change(rows6, order, P, C, dP, dC): the change of a cut's velocity (1) or acceleration (2) "
        "rows along a change of its frames' motions (core.hpp)");
  nb::class_<Core>(m, "Core")
      .def(nb::init<nb::object, const std::vector<int>&, const std::vector<int>&, const std::vector<int>&,
                    const std::vector<int>&, const Eigen::Ref<const RowMatrix>&, const Eigen::Ref<const RowMatrix>&,
                    const std::vector<MatrixXd>&, const std::vector<MatrixXd>&, const std::vector<int>&,
                    const std::vector<int>&, const std::vector<int>&, const std::vector<int>&, const VectorXd&,
                    const std::vector<std::vector<int>>&, const std::vector<std::vector<int>>&, double>())
      .def_prop_ro("model", &Core::model)
      .def_prop_ro("same_structure", &Core::same_structure)
      .def_prop_ro("nq", &Core::nq)
      .def_prop_ro("nv", &Core::nv)
      .def_prop_ro("idx_q", &Core::idx_q)
      .def_prop_ro("idx_v", &Core::idx_v)
      .def_prop_rw("tol", &Core::tol, &Core::set_tol)
      .def_prop_rw("certify_every", &Core::certify_every, &Core::set_certify_every,
                   "the certification dial of the range and rate modes: 1 every pose, k >= 2 every k-th pose and "
                   "a range's last, 0 a range's last, -1 none (residuals only)")
      .def_prop_ro("iterations", &Core::iterations)
      .def_prop_ro("solve_blocks", &Core::solve_blocks)
      .def_prop_ro("moved", &Core::moved)
      .def("residual", &Core::residual)
      .def("full_residual", &Core::full_residual)
      .def("jacobian", &Core::jacobian, nb::arg("newton") = false)
      .def("drift", &Core::drift)
      .def("errors6", &Core::errors6)
      .def("translation_rows", &Core::translation_rows)
      .def("signs", &Core::signs)
      .def("correct",
           [](Core& core, VectorXd q, const VectorXd& drivers, int max_iterations) {
             core.check_structure();
             double residual = NAN;
             const bool ok = core.correct(q, drivers, max_iterations, residual);
             return nb::make_tuple(q, ok ? nb::cast(residual) : nb::none());
           })
      .def("close", &Core::close_py, nb::arg("q"), nb::arg("drivers"), nb::arg("max_iterations"),
           nb::arg("polish_within") = true)
      .def("follow_path", &Core::follow_path_py)
      .def("rates_at", &Core::rates_at)
      .def("set_pivots", &Core::set_pivots)
      .def("follow", &Core::follow)
      .def("node", &Core::node)
      .def("rates", &Core::rates)
      .def("set_task", &Core::set_task)
      .def("set_rate_options", &Core::set_rate_options)
      .def_prop_ro("rate_columns", &Core::rate_columns)
      .def("stacked_jacobian", &Core::stacked_jacobian)
      .def("pinocchio_passes", &Core::pinocchio_passes)
      .def("set_kernel", &Core::set_kernel, "set_kernel(path): the kinematic passes from a generated kernel (kernel.cpp)")
      .def("clear_kernel", &Core::clear_kernel, "clear_kernel(): Pinocchio's generic passes again")
      .def_prop_ro("kernel_path", &Core::kernel_path)
      .def_prop_ro("kernel_stale", &Core::kernel_stale);
}
