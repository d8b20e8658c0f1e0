// The library's errors as the Python classes of caliper.errors, and the small conversions every
// part uses.
#include <omniORB4/CORBA.h>

#include <algorithm>
#include <cmath>

#include "binding.h"
#include "caliper/calibration/calibration.h"
#include "caliper/experiment/experiment.h"
#include "caliper/recording/recording.h"
#include "caliper/rtc/client_orb.h"
#include "caliper/rtc/naming.h"

namespace caliper::python {

CallScope::CallScope(double timeout_s) {
  thread_local rtc::OmniThread known;  // once per thread, for its lifetime
  (void)known;
  // 0 would fall back to the ORB's global deadline (the first session's): "none" is the longest
  omniORB::setClientThreadCallTimeout(
      timeout_s > 0 ? static_cast<CORBA::ULong>(std::min(timeout_s * 1000, 4e9)) : 0xFFFFFFFFu);
}

CallScope::~CallScope() { omniORB::setClientThreadCallTimeout(0); }

namespace {

// Raises caliper.errors.NAME(message) with `attributes` set on the exception object.
void Raise(const char* name, const std::string& message, const py::dict& attributes = {}) {
  py::object cls = py::module_::import("caliper.errors").attr(name);
  py::object error = cls(message);
  for (auto item : attributes) py::setattr(error, item.first, item.second);
  PyErr_SetObject(cls.ptr(), error.ptr());
}

void Translate(std::exception_ptr p) {
  try {
    std::rethrow_exception(p);
  } catch (const client::ConnectionError& e) {
    Raise("ConnectionError", e.what(), py::dict(py::arg("address") = e.address()));
  } catch (const client::UnknownIdError& e) {
    Raise("UnknownId", e.what(), py::dict(py::arg("id") = e.id()));
  } catch (const client::InvalidParameterError& e) {
    Raise("InvalidParameter", e.what());
  } catch (const client::NotAvailableError& e) {
    Raise("NotAvailable", e.what());
  } catch (const client::LoadFailedError& e) {
    Raise("LoadFailed", e.what());
  } catch (const client::LimitExceededError& e) {
    Raise("LimitExceeded", e.what(), py::dict(py::arg("limit") = e.limit()));
  } catch (const client::RunFailedError& e) {
    Raise("RunFailed", e.what());
  } catch (const client::EditRefusedError& e) {
    Raise("EditRefused", e.what());
  } catch (const client::SetupError& e) {
    Raise("SetupError", e.what());
  } catch (const client::Failure& e) {
    Raise("Error", e.what());
  } catch (const experiment::FormatError& e) {
    Raise("FormatError", e.what());
  } catch (const calibration::SpecError& e) {
    Raise("FormatError", e.what());
  } catch (const recording::RecordingError& e) {
    Raise("RecordingError", e.what());
  } catch (const CORBA::SystemException& e) {
    Raise("ConnectionError", "a Caliper process cannot be reached: " + rtc::Describe(e));
  } catch (const CORBA::Exception& e) {
    Raise("Error", rtc::Describe(e));
  }
}

}  // namespace

void BindErrors(py::module_& m) {
  (void)m;
  py::register_exception_translator(&Translate);
}

std::vector<double> FiniteValues(const py::handle& value, const char* argument) {
  if (py::isinstance<py::str>(value) || py::isinstance<py::bytes>(value) || value.is_none())
    throw py::type_error(std::string(argument) + " must be a number or an array of numbers, not " +
                         std::string(py::str(py::type::of(value).attr("__name__"))));
  py::array_t<double, py::array::c_style | py::array::forcecast> array;
  try {
    array = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(value);
  } catch (const py::error_already_set&) {
  }
  if (!array) {
    PyErr_Clear();
    throw py::type_error(std::string(argument) + " must be a number or an array of numbers, not " +
                         std::string(py::str(py::type::of(value).attr("__name__"))));
  }
  std::vector<double> out(array.data(), array.data() + array.size());
  for (size_t i = 0; i < out.size(); ++i)
    if (!std::isfinite(out[i]))
      throw py::value_error(std::string(argument) + " must be finite; element " +
                            std::to_string(i) + " is " + (std::isnan(out[i]) ? "NaN" : "infinite"));
  return out;
}

std::vector<std::string> IdList(const py::handle& ids, const char* argument) {
  if (py::isinstance<py::str>(ids)) return {ids.cast<std::string>()};
  std::vector<std::string> out;
  if (!py::isinstance<py::iterable>(ids))
    throw py::type_error(std::string(argument) + " must be an id or a list of ids, not " +
                         std::string(py::str(py::type::of(ids).attr("__name__"))));
  for (auto item : ids) {
    if (!py::isinstance<py::str>(item))
      throw py::type_error(std::string(argument) + " must hold strings, not " +
                           std::string(py::str(py::type::of(item).attr("__name__"))));
    out.push_back(item.cast<std::string>());
  }
  return out;
}

std::vector<py::ssize_t> ChannelShape(uint32_t rows, uint32_t cols) {
  if (rows == 1 && cols == 1) return {};
  if (cols == 1) return {static_cast<py::ssize_t>(rows)};
  return {static_cast<py::ssize_t>(rows), static_cast<py::ssize_t>(cols)};
}

}  // namespace caliper::python
