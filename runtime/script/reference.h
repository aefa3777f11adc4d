#pragma once

/// \file
/// \brief The script language's reference page, generated from the command table: every
/// command with its form, values and default. `basalt help script` prints it; the build target
/// `script-reference` writes it to docs/script-reference.md, and a test checks that the file
/// and the table agree.

#include <string>

namespace basalt::script {

/// \brief The reference page, in Markdown.
std::string scriptReference();

}  // namespace basalt::script
