#pragma once
// The errors of the client library. Every call into a Caliper process that fails raises one of
// these, carrying a message a user can read as it stands (it names the component or file, the id
// and the Model's own reason); the classes mirror the IDL's user exceptions so that a caller (a
// command-line verb, a GUI, the Python package) can tell them apart.

#include <cstdint>
#include <stdexcept>
#include <string>

namespace caliper::client {

/// Base of every error the library raises.
class Failure : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A process could not be reached (CORBA TRANSIENT, COMM_FAILURE, TIMEOUT, OBJECT_NOT_EXIST) or
/// the naming service does not answer; `address()` names what was called.
class ConnectionError : public Failure {
 public:
  ConnectionError(const std::string& what, std::string address)
      : Failure(what), address_(std::move(address)) {}
  const std::string& address() const { return address_; }

 private:
  std::string address_;
};

/// An id (actuator, channel, body, subscription) the Model does not have; `id()` names it.
class UnknownIdError : public Failure {
 public:
  UnknownIdError(const std::string& what, std::string id) : Failure(what), id_(std::move(id)) {}
  const std::string& id() const { return id_; }

 private:
  std::string id_;
};

/// A value the Model refuses (NaN, a wrong shape, out of its range).
class InvalidParameterError : public Failure {
 public:
  using Failure::Failure;
};

/// The Model cannot do it now (no scene, faulted, running an experiment, replaying).
class NotAvailableError : public Failure {
 public:
  using Failure::Failure;
};

/// A scene that could not be loaded; the message names the file and the problem.
class LoadFailedError : public Failure {
 public:
  using Failure::Failure;
};

/// More than one call may ask for; `limit()` is the bound.
class LimitExceededError : public Failure {
 public:
  LimitExceededError(const std::string& what, uint64_t limit) : Failure(what), limit_(limit) {}
  uint64_t limit() const { return limit_; }

 private:
  uint64_t limit_;
};

/// A run whose physics faulted (NaN, explosion); the message is the Model's report.
class RunFailedError : public Failure {
 public:
  using Failure::Failure;
};

/// A scene edit the Model refused; nothing changed.
class EditRefusedError : public Failure {
 public:
  using Failure::Failure;
};

}  // namespace caliper::client
