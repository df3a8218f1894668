#include "cli.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "foxi/viz/view_options.hpp"

namespace foxi::cli {

bool Args::flag(std::string_view name) {
  for (auto it = args_.begin(); it != args_.end(); ++it) {
    if (*it == name) {
      args_.erase(it);
      taken_.emplace_back(name);
      return true;
    }
  }
  return false;
}

bool Args::has_option(std::string_view name) const {
  for (const std::string& a : args_)
    if (a == name) return true;
  return false;
}

bool Args::flag_with_file(std::string_view name, std::string_view suffix, std::string& file) {
  file.clear();
  for (auto it = args_.begin(); it != args_.end(); ++it) {
    if (*it != name) continue;
    taken_.emplace_back(name);
    const auto next = it + 1;
    if (next != args_.end() && next->size() > suffix.size() &&
        next->compare(next->size() - suffix.size(), suffix.size(), suffix) == 0) {
      file = *next;
      args_.erase(it, next + 1);
    } else {
      args_.erase(it);
    }
    return true;
  }
  return false;
}

std::vector<std::string> Args::take_after(std::string_view marker) {
  for (auto it = args_.begin(); it != args_.end(); ++it) {
    if (*it != marker) continue;
    std::vector<std::string> rest(it + 1, args_.end());
    args_.erase(it, args_.end());
    return rest;
  }
  return {};
}

Args::Args(std::vector<std::string> args) : args_(split_option_values(std::move(args))) {}

std::string Args::option(std::string_view name, std::string fallback) {
  for (auto it = args_.begin(); it != args_.end(); ++it) {
    if (*it == name) {
      if (it + 1 == args_.end()) throw UsageError("option " + std::string(name) + " needs a value");
      std::string value = *(it + 1);
      // An empty value (--opacity-curve '' from a script's unset variable) would read as the option
      // left out, and its default be used in silence.
      if (value.empty()) throw UsageError("option " + std::string(name) + " takes a value, not an empty one");
      args_.erase(it, it + 2);
      taken_.emplace_back(name);
      return value;
    }
  }
  return fallback;
}

std::vector<std::string> Args::positional(std::size_t min, std::size_t max, std::string_view usage) {
  for (const std::string& a : args_) {
    if (a.size() > 1 && a[0] == '-' && a[1] == '-') {
      // The same option twice would silently lose one of its values: say so, not "unknown".
      if (std::find(taken_.begin(), taken_.end(), a) != taken_.end())
        throw UsageError("option " + a + " given twice (give it once)\nusage: " + std::string(usage));
      throw UsageError("unknown option " + a + "\nusage: " + std::string(usage));
    }
  }
  if (args_.size() < min || args_.size() > max) {
    throw UsageError("expected " +
                     (min == max ? std::to_string(min) : std::to_string(min) + " to " + std::to_string(max)) +
                     " arguments, got " + std::to_string(args_.size()) + "\nusage: " + std::string(usage));
  }
  return args_;
}

std::vector<double> parse_numbers(const std::string& s, const char* what) {
  try {
    return parse_number_list(s, what);
  } catch (const OptionError& e) {
    throw UsageError(e.what());
  }
}

std::string json_number(double v) {
  if (!std::isfinite(v)) return "null";
  char buf[32];
  auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

}  // namespace foxi::cli
