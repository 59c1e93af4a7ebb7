// prtr merge SHARDS... -o FILE.prtx: the shards of `prtr bake --shard k/n` into the .prtx
// one process would have written, after checking they belong together.
#include "commands.h"
#include "flag_checks.h"

#include "prt/transfer_file.h"
#include "prt/transfer_shard.h"

#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

namespace prtr_app {

Runner add_merge_command(CLI::App& app) {
  struct Options {
    std::vector<std::string> shards;
    std::string output;
  };
  auto opt = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "merge", "Merge the shards of prtr bake --shard k/n into one .prtx (refuses a mismatch)");
  cmd->add_option("SHARDS", opt->shards, "All n shard files, in any order")->required();
  cmd->add_option("-o,--output", opt->output, "Transfer file to write (.prtx)")->required();

  return [opt] {
    std::vector<common::NamedPath> inputs;
    for (const std::string& shard : opt->shards) inputs.push_back({"SHARD", shard});
    check_outputs({{"-o", opt->output}}, inputs);
    std::vector<std::filesystem::path> paths(opt->shards.begin(), opt->shards.end());
    prt::merge_shards(paths, opt->output);
    const prt::TransferSet header = prt::read_transfer_header(opt->output);
    std::printf("merged      %zu shards -> %s: %s, order %d, %llu vertices\n", paths.size(),
                opt->output.c_str(), prt::kTransferKindNames.name(header.kind), header.order,
                static_cast<unsigned long long>(header.vertex_count));
  };
}

}  // namespace prtr_app
