#include "tools/chorus/kept_outputs.h"

#include <sstream>

namespace chorus::cli {

namespace {

std::vector<std::string> itemsOf(const std::string& list) {
  std::vector<std::string> items;
  std::stringstream stream(list);
  std::string item;
  while (std::getline(stream, item, ',')) items.push_back(item);
  if (list.empty() || list.back() == ',') items.emplace_back();  // an empty last item
  return items;
}

}  // namespace

void KeptOutputs::addFlag(CLI::App& cmd) {
  cmd.add_option_function<std::string>(
         "--keep",
         [this](const std::string& list) {
           for (const std::string& item : itemsOf(list))
             (item == "members" ? members : weights) = true;
         },
         "Also write: members (each member's own output, <member>.exr), weights (the weight "
         "maps, weights.exr); comma-separated")
      ->check(CLI::Validator(
          [](std::string& list) -> std::string {
            for (const std::string& item : itemsOf(list))
              if (item != "members" && item != "weights")
                return "'" + item + "' is not members or weights";
            return {};
          },
          "members,weights"));
}

nlohmann::ordered_json outputsJson(const std::vector<std::string>& written,
                                   const std::vector<LeftOut>& leftOut) {
  nlohmann::ordered_json files = nlohmann::ordered_json::object();
  for (const LeftOut& l : leftOut) files[l.file] = l.how;
  return {{"written", written}, {"left_out", files}};
}

}  // namespace chorus::cli
