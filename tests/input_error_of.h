#pragma once
// What a user is told about bad input: the message of the InputError that f() throws, or
// "no error" when it throws none (the bad-input tests compare these strings).
#include <string>

#include "common/errors.h"

template <typename F>
std::string input_error_of(F&& f) {
  try {
    f();
  } catch (const treeanim::InputError& error) {
    return error.what();
  }
  return "no error";
}
