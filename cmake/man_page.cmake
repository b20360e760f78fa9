# Writes OUT, emaki(1), from the built binary EMAKI: `emaki --version`, `emaki --help`,
# `emaki COMMAND --help` for each command the help lists ("  NAME  summary" lines), and
# `emaki COMMAND SUB --help` for each sub-command a command's help lists the same way (farm, qa,
# task). Made at build time from the CLI's own text, so the page cannot drift from the options.
# A --help that fails fails the build.

function(emaki_output var)
  execute_process(COMMAND "${EMAKI}" ${ARGN} OUTPUT_VARIABLE out ERROR_VARIABLE err
                  RESULT_VARIABLE failed)
  if(failed)
    list(JOIN ARGN " " command)
    message(FATAL_ERROR "man page: 'emaki ${command}' failed (${failed}): ${err}")
  endif()
  set(${var} "${out}" PARENT_SCOPE)
endfunction()

# Text as roff: backslashes escaped, a line starting with . or ' not read as a request.
function(roff_text var text)
  string(REPLACE "\\" "\\e" text "${text}")
  string(REGEX REPLACE "(^|\n)([.'])" "\\1\\\\&\\2" text "${text}")
  set(${var} "${text}" PARENT_SCOPE)
endfunction()

emaki_output(version_line --version)
string(STRIP "${version_line}" version_line)
emaki_output(usage --help)

set(page ".TH EMAKI 1 \"\" \"${version_line}\" \"User Commands\"
.SH NAME
emaki \\- stylize 3D animation by example
.SH SYNOPSIS
.B emaki
\\fICOMMAND\\fR [\\fIOPTIONS\\fR]
.br
.B emaki
\\fB\\-\\-version\\fR | \\fB\\-\\-help\\fR
.SH DESCRIPTION
")
roff_text(text "${usage}")
string(APPEND page ".nf\n${text}.fi\n.SH COMMANDS\n")

# The names a help lists as "  NAME  summary" (two spaces at least: not CLI11's "  NAME TYPE").
function(listed_names var text)
  set(names "")
  string(REGEX MATCHALL "\n  [a-z]+  +[^ \n]" found "\n${text}")
  foreach(item IN LISTS found)
    string(REGEX REPLACE "^\n  ([a-z]+) .*" "\\1" name "${item}")
    list(APPEND names "${name}")
  endforeach()
  set(${var} "${names}" PARENT_SCOPE)
endfunction()

# One section per command (and sub-command) in the order the help lists them.
listed_names(commands "${usage}")
foreach(name IN LISTS commands)
  emaki_output(help ${name} --help)
  roff_text(text "${help}")
  string(APPEND page ".SS emaki ${name}\n.nf\n${text}.fi\n")
  listed_names(subs "${help}")
  foreach(sub IN LISTS subs)
    emaki_output(help ${name} ${sub} --help)
    roff_text(text "${help}")
    string(APPEND page ".SS emaki ${name} ${sub}\n.nf\n${text}.fi\n")
  endforeach()
endforeach()

string(APPEND page ".SH FILES
.TP
.I PREFIX/share/emaki/docs
the guide (guide.md), the shot file reference (shot_file.md), the farm, Python and Blender pages
.TP
.I PREFIX/share/emaki/examples
the bundled shots; copy one to a writable folder and run `emaki run shot.toml`
")
file(WRITE "${OUT}" "${page}")
