// The options whose values are lists or carry units (a resolution, a stop rule, folders, the
// adaptive parts, a memory size): each parses its own small grammar, so each is a function of
// its own, kept apart from the table's rows (option_table.cpp).
#pragma once

#include "options/options.h"

namespace pb::option_lists {

OptionSpec resolution();
OptionSpec stop_rule();
OptionSpec asset_dirs();
OptionSpec adaptive();
OptionSpec max_memory();

}  // namespace pb::option_lists
