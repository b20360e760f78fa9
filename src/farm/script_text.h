// What a batch script may take from a shot file or a command line. Every value written into a
// Slurm script (`#SBATCH` directives and the shell body) passes through one of these: a value
// either goes in so that sbatch and the shell read back exactly that value, or it is refused
// with an emaki::Error naming its subject (the option, config key or file it came from).
#pragma once

#include <string>
#include <string_view>

namespace emaki::farm {

// Throws Error(subject) unless `value` is valid UTF-8 free of control characters (NUL, newline,
// CR, tab, DEL...): a line of a script cannot hold them, and an error line could not show them.
void check_script_text(std::string_view value, const std::string& subject);

// `value` as one word of a POSIX shell: single-quoted, each ' written as '\''; $(), backticks,
// double quotes, spaces and % stay literal. Refuses what check_script_text refuses.
std::string shell_word(std::string_view value, const std::string& subject);

// `value` as the value of an `#SBATCH --key=value` line. sbatch splits directive lines at
// blanks and has its own quoting, so only letters, digits and the characters of `allowed` are
// taken, and no leading '-' (it would read as another option). Returns `value`.
std::string directive_value(std::string_view value, const std::string& subject,
                            std::string_view allowed);

// `value` as the literal start of a Slurm filename pattern (sbatch's --output): every % doubled,
// since Slurm expands %j, %A, ... anywhere in the path. A backslash is refused: it would turn
// the pattern's expansion off. Refuses what check_script_text refuses.
std::string slurm_pattern_literal(std::string_view value, const std::string& subject);

// A job name made from free text: every byte that is not a letter, digit, '.', '_' or '-'
// becomes '_', so any shot name yields a name sbatch, squeue and a directive take as it is.
std::string job_name_part(std::string_view text);

}  // namespace emaki::farm
