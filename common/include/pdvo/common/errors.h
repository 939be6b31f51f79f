// Project exception types and the throwing check macro.
//
// Bad input at a public entry point (a missing file, a malformed file, an invalid argument) throws one of the
// types below with a message that names the file and the problem. Libraries never exit or abort; the `pdvo`
// command catches these in main and prints them as one line. Failures expected per frame are values, not
// exceptions.
#pragma once

#include <sstream>
#include <stdexcept>
#include <string>

namespace pdvo {

// Base of every project exception.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A file could not be opened, read, decoded or written.
class IoError : public Error {
 public:
  using Error::Error;
};

// A file or value was read but its content is malformed or inconsistent.
class FormatError : public Error {
 public:
  using Error::Error;
};

// A caller passed an invalid argument or option.
class InvalidArgument : public Error {
 public:
  using Error::Error;
};

}  // namespace pdvo

// PDVO_THROW_CHECK(cond, Type, message stream): throws Type(message) when cond is false. The message is a
// stream expression, e.g. PDVO_THROW_CHECK(n > 0, pdvo::FormatError, path << ": no poses").
#define PDVO_THROW_CHECK(cond, Type, msg) \
  do {                                    \
    if (!(cond)) {                        \
      std::ostringstream pdvo_check_os_;  \
      pdvo_check_os_ << msg;              \
      throw Type(pdvo_check_os_.str());   \
    }                                     \
  } while (false)

// PDVO_THROW(Type, message stream): throws unconditionally.
#define PDVO_THROW(Type, msg) PDVO_THROW_CHECK(false, Type, msg)
