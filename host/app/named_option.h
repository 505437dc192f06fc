// named_option.h — a command-line option whose words are an enum's name table (core/names.h):
// CLI11 checks the word against the table (its usual "not in {...}" error) and the enum is set
// from the same table, so an option is parsed once, into its type, with its check beside it.
#pragma once
#include <string>
#include <utility>

#include <CLI/CLI.hpp>

#include "core/names.h"

namespace obscura::app {

template <typename E, std::size_t N>
CLI::Option* addNamedOption(CLI::App& command, std::string flag, E& target, const NameTable<E, N>& table,
                            std::string help) {
  return command
      .add_option_function<std::string>(
          std::move(flag), [&target, &table](const std::string& name) { target = *valueNamed(table, name); },
          std::move(help))
      ->check(CLI::IsMember(namesOf(table)));
}

} // namespace obscura::app
