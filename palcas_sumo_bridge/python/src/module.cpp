// _palcas_env: the pybind11 layer of palcas_env (palcas_env/__init__.py is the Python API).
// Converts Python values to the C++ core's and back; every check of meaning is in the core
// (parallel_env.cpp), which throws std::invalid_argument (ValueError here) naming what was
// wrong and leaves the environment as it was.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <palcas_core/common/build_info.h>

#include <cmath>
#include <memory>
#include <string>

#include "parallel_env.h"

namespace py = pybind11;
using namespace palcas;
using namespace palcas::pyenv;

namespace {

ros::ParamValue toParam(const std::string& name, const py::handle& v) {
  ros::ParamValue p;
  if (py::isinstance<py::bool_>(v)) {
    p.type = ros::ParamValue::Type::kBool;
    p.b = v.cast<bool>();
  } else if (py::isinstance<py::int_>(v)) {
    p.type = ros::ParamValue::Type::kInt;
    p.i = v.cast<int>();
  } else if (py::isinstance<py::float_>(v)) {
    p.type = ros::ParamValue::Type::kDouble;
    p.d = v.cast<double>();
  } else if (py::isinstance<py::str>(v)) {
    p.type = ros::ParamValue::Type::kString;
    p.s = v.cast<std::string>();
  } else if (py::isinstance<py::list>(v) || py::isinstance<py::tuple>(v)) {
    p.type = ros::ParamValue::Type::kList;
    for (const py::handle& item : v) p.list.push_back(toParam(name, item));
  } else {
    throw py::type_error("parameter '" + name + "': unsupported value type " +
                         py::str(py::type::of(v)).cast<std::string>());
  }
  return p;
}

std::shared_ptr<const ros::ParamTree> toTree(const py::dict& params) {
  auto tree = std::make_shared<ros::ParamTree>();
  for (const auto& [key, value] : params) {
    const std::string name = py::str(key).cast<std::string>();
    (*tree)[name] = toParam(name, value);
  }
  return tree;
}

py::array_t<float> toArray(const std::vector<float>& v) {
  py::array_t<float> a(static_cast<py::ssize_t>(v.size()));
  std::copy(v.begin(), v.end(), a.mutable_data());
  return a;
}

py::tuple toPython(const StepResult& r) {
  py::dict obs, rewards, terminations, truncations, infos;
  for (const auto& [agent, state] : r.observations) obs[py::str(agent)] = toArray(state);
  for (const auto& [agent, reward] : r.rewards) rewards[py::str(agent)] = reward;
  for (const auto& [agent, t] : r.terminations) terminations[py::str(agent)] = t;
  for (const auto& [agent, t] : r.truncations) truncations[py::str(agent)] = t;
  py::dict header;
  header["step"] = r.step;
  header["time_s"] = r.time_s;
  header["episode_over"] = r.episode_over;
  return py::make_tuple(obs, rewards, terminations, truncations, header, r.agents);
}

nn::Matrix statesFrom(const py::array_t<float, py::array::c_style | py::array::forcecast>& states, int size) {
  if (states.ndim() != 2 || states.shape(1) != size)
    throw py::value_error("states must be an array of shape (n, " + std::to_string(size) + ")");
  nn::Matrix m(size, static_cast<nn::Index>(states.shape(0)));
  auto s = states.unchecked<2>();
  for (py::ssize_t j = 0; j < states.shape(0); ++j)
    for (py::ssize_t i = 0; i < size; ++i) m(i, j) = s(j, i);
  return m;
}

}  // namespace

PYBIND11_MODULE(_palcas_env, m) {
  m.doc() = "The C++ core of palcas_env (use the palcas_env package, not this module)";

  py::class_<ParallelEnvCore>(m, "ParallelEnvCore")
      .def(py::init([](const py::dict& params, const std::string& bridge_ns) {
             EnvParams p;
             p.tree = toTree(params);
             p.bridge_ns = bridge_ns;
             py::gil_scoped_release release;
             return std::make_unique<ParallelEnvCore>(p);
           }),
           py::arg("params"), py::arg("bridge_ns") = "/palcas_sumo_bridge")
      .def("reset",
           [](ParallelEnvCore& env, std::optional<unsigned> seed) {
             StepResult r;
             {
               py::gil_scoped_release release;
               r = env.reset(seed);
             }
             return toPython(r);
           },
           py::arg("seed") = py::none())
      .def("step",
           [](ParallelEnvCore& env, const std::map<std::string, std::pair<int, double>>& actions) {
             std::map<std::string, AgentAction> a;
             for (const auto& [agent, action] : actions) a[agent] = AgentAction{action.first, action.second};
             StepResult r;
             {
               py::gil_scoped_release release;
               r = env.step(a);
             }
             return toPython(r);
           })
      .def_property_readonly("agents", &ParallelEnvCore::agents)
      .def_property_readonly("rsu_ids", &ParallelEnvCore::rsuIds)
      .def_property_readonly("state_size", &ParallelEnvCore::stateSize)
      .def_property_readonly("num_lanes", &ParallelEnvCore::numLanes)
      .def_property_readonly("out_dir", &ParallelEnvCore::outDir)
      .def_property_readonly("episode_running", &ParallelEnvCore::episodeRunning)
      .def_property_readonly("decision_period_steps", &ParallelEnvCore::decisionPeriodSteps)
      .def_property_readonly("duration_s", [](const ParallelEnvCore& env) { return env.bridgeOptions().scenario.duration_s; })
      .def_property_readonly("seed", [](const ParallelEnvCore& env) { return env.bridgeOptions().scenario.seed; })
      .def("accel_bounds", [](const ParallelEnvCore& env, const std::string& rsu_id) {
        const PdqnConfig& c = env.rsuOptions(rsu_id).controller.pdqn;
        return py::make_tuple(c.accel_min_mps2, c.accel_max_mps2);
      });

  py::class_<PolicyCore>(m, "PolicyCore")
      .def(py::init<const std::string&, const ParallelEnvCore&>(), py::arg("folder"), py::arg("env"))
      .def("act",
           [](PolicyCore& policy, const std::map<std::string, std::vector<float>>& observations) {
             std::map<std::string, AgentAction> a;
             {
               py::gil_scoped_release release;
               a = policy.act(observations);
             }
             py::dict out;
             for (const auto& [agent, action] : a)
               out[py::str(agent)] = py::make_tuple(action.advisory, action.accel_mps2);
             return out;
           })
      .def("evaluate",
           [](PolicyCore& policy, const std::string& rsu_id,
              const py::array_t<float, py::array::c_style | py::array::forcecast>& states) {
             const nn::Matrix s = statesFrom(states, policy.config(rsu_id).state_size);
             nn::Matrix q, accel;
             policy.evaluate(rsu_id, s, q, accel);
             py::array_t<float> q_out({static_cast<py::ssize_t>(s.cols()), static_cast<py::ssize_t>(q.rows())});
             py::array_t<float> a_out(static_cast<py::ssize_t>(s.cols()));
             auto qa = q_out.mutable_unchecked<2>();
             auto aa = a_out.mutable_unchecked<1>();
             for (nn::Index j = 0; j < s.cols(); ++j) {
               for (nn::Index i = 0; i < q.rows(); ++i) qa(j, i) = q(i, j);
               aa(j) = accel(0, j);
             }
             return py::make_tuple(q_out, a_out);
           },
           py::arg("rsu_id"), py::arg("states"))
      .def("export_model",
           [](const PolicyCore& policy, const std::string& rsu_id) {
             const ModelBlob blob = policy.exportModel(rsu_id);
             const PdqnConfig& c = policy.config(rsu_id);
             py::dict config;
             config["state_size"] = c.state_size;
             config["accel_min_mps2"] = c.accel_min_mps2;
             config["accel_max_mps2"] = c.accel_max_mps2;
             config["multi_pass"] = c.multi_pass;
             return py::make_tuple(blob.layout_id, toArray(blob.values), config);
           },
           py::arg("rsu_id"))
      .def_property_readonly("model_files", &PolicyCore::modelFiles)
      .def_property_readonly("rsu_ids", &PolicyCore::rsuIds);

  m.def("build_info", [] {
    const BuildInfo b = buildInfo();
    return py::dict(py::arg("core_arch") = b.arch, py::arg("core_simd") = b.simd, py::arg("cpu") = b.cpu);
  });
}
