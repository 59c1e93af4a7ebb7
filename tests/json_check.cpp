// tests/json_check.cpp: lets tests/cli_test.sh judge prtr's JSON with the same library that
// writes it, because a minimal Debian root has no python3 or jq to do it.
//   json_check FILE|-                 exit 0 when the whole input is one valid JSON document
//   json_check FILE|- POINTER...      also prints the value at each JSON pointer, one a line
// Strings print unquoted, everything else as JSON. Exit 1 on invalid JSON or a missing
// pointer (naming it), 2 on usage.
#include <nlohmann/json.hpp>

#include <cstdio>
#include <fstream>
#include <iostream>
#include <iterator>
#include <string>

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: json_check FILE|- [JSON-POINTER...]\n");
    return 2;
  }
  const std::string source = argv[1];
  std::string text;
  if (source == "-") {
    text.assign(std::istreambuf_iterator<char>(std::cin), {});
  } else {
    std::ifstream in(source, std::ios::binary);
    if (!in) {
      std::fprintf(stderr, "json_check: cannot read %s\n", source.c_str());
      return 1;
    }
    text.assign(std::istreambuf_iterator<char>(in), {});
  }
  nlohmann::json document;
  try {
    document = nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    std::fprintf(stderr, "json_check: %s is not valid JSON: %s\n", source.c_str(), e.what());
    return 1;
  }
  for (int i = 2; i < argc; ++i) {
    try {
      const nlohmann::json& value = document.at(nlohmann::json::json_pointer(argv[i]));
      std::cout << (value.is_string() ? value.get<std::string>() : value.dump()) << '\n';
    } catch (const nlohmann::json::exception& e) {
      std::fprintf(stderr, "json_check: %s: no %s (%s)\n", source.c_str(), argv[i], e.what());
      return 1;
    }
  }
  return 0;
}
