// sphfsi: a tiny command-line parser for the example drivers: `--name value` flags with defaults and help text.
#pragma once

#include <sphfsi/core/error.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace sphfsi::io {

class CommandLine {
 public:
  /// description: one paragraph printed by --help.
  CommandLine(int argc, char** argv, std::string description) : description_(std::move(description)) {
    for (int i = 1; i < argc; ++i) args_.emplace_back(argv[i]);
  }

  /// Registers a flag and returns its value (or the default). Call for every flag before finish().
  std::string get(std::string_view name, std::string_view default_value, std::string_view help) {
    flags_.push_back({std::string(name), std::string(default_value), std::string(help)});
    for (std::size_t i = 0; i < args_.size(); ++i) {
      if (args_[i] == fmt::format("--{}", name)) {
        if (i + 1 >= args_.size()) throw InputError(fmt::format("--{} needs a value", name));
        used_.push_back(i);
        used_.push_back(i + 1);
        return args_[i + 1];
      }
    }
    return std::string(default_value);
  }

  double get_number(std::string_view name, double default_value, std::string_view help) {
    const std::string s = get(name, fmt::format("{}", default_value), help);
    const auto v = number_from(s);
    if (!v) throw InputError(fmt::format("--{} = '{}' is not a number", name, s));
    return *v;
  }

  /// A comma-separated list of numbers ("0.6,1.0,1.3"); an item that is not a number is an InputError naming the
  /// flag and the item. An empty value gives an empty list.
  std::vector<double> get_numbers(std::string_view name, std::string_view default_value, std::string_view help) {
    const std::string s = get(name, default_value, help);
    std::vector<double> values;
    std::size_t begin = 0;
    while (begin <= s.size() && !s.empty()) {
      const std::size_t comma = std::min(s.find(',', begin), s.size());
      const std::string item = s.substr(begin, comma - begin);
      const auto v = number_from(item);
      if (!v)
        throw InputError(
            fmt::format("--{} = '{}': item '{}' is not a number (a comma-separated list of numbers)", name, s, item));
      values.push_back(*v);
      begin = comma + 1;
    }
    return values;
  }

  /// An on | off flag: true for "on"; any other value than "on" or "off" is an InputError naming the flag.
  bool get_switch(std::string_view name, bool default_on, std::string_view help) {
    const std::string s = get(name, default_on ? "on" : "off", help);
    if (s != "on" && s != "off")
      throw InputError(fmt::format("--{} = '{}' is invalid: valid values are on, off", name, s));
    return s == "on";
  }

  /// Returns false (after printing the help) if --help was given; throws on unknown flags.
  bool finish() {
    for (std::size_t i = 0; i < args_.size(); ++i) {
      if (args_[i] == "--help" || args_[i] == "-h") {
        print_help();
        return false;
      }
    }
    for (std::size_t i = 0; i < args_.size(); ++i) {
      bool known = false;
      for (std::size_t u : used_) known = known || u == i;
      if (!known) throw InputError(fmt::format("unknown argument '{}' (see --help)", args_[i]));
    }
    return true;
  }

  void print_help() const {
    fmt::print("{}\n\nOptions:\n", description_);
    for (const auto& f : flags_) fmt::print("  --{:<14} {} (default: {})\n", f.name, f.help, f.default_value);
    fmt::print("  --help           print this help\n");
  }

 private:
  /// The whole text as a number (strtod), or nothing if it is empty or has anything after the number.
  static std::optional<double> number_from(const std::string& text) {
    char* end = nullptr;
    const double v = std::strtod(text.c_str(), &end);
    if (end == text.c_str() || *end != '\0') return std::nullopt;
    return v;
  }

  struct Flag {
    std::string name, default_value, help;
  };
  std::string description_;
  std::vector<std::string> args_;
  std::vector<Flag> flags_;
  std::vector<std::size_t> used_;
};

}  // namespace sphfsi::io
