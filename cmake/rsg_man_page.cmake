# cmake -P rsg_man_page.cmake: one tool's manual page, generated from its --help by help2man and
# compressed the way Debian ships man pages (gzip -9n: no name or time stamp, reproducible). The NAME
# line is the first line of --help (CLI11's app description), so nothing here can drift from the tool.
#   -DTOOL=<path of the executable> -DVERSION=<project version> -DHELP2MAN=<path> -DOUT=<file.1.gz>
#   -DPROFILES=<the installed profiles directory>
foreach(var TOOL VERSION HELP2MAN OUT PROFILES)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "rsg_man_page.cmake: -D${var}=... is missing")
  endif()
endforeach()
get_filename_component(name "${TOOL}" NAME)
get_filename_component(dir "${OUT}" DIRECTORY)
file(MAKE_DIRECTORY "${dir}")
# The defaults --help shows are the installed ones, not the build tree's (rsg_echo --profiles).
set(ENV{RSG_PROFILES_DIR} "${PROFILES}")
execute_process(COMMAND "${TOOL}" --help OUTPUT_VARIABLE help RESULT_VARIABLE status)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "${name} --help exited ${status}")
endif()
string(REGEX MATCH "^[^\n]*" summary "${help}")
string(REGEX REPLACE "[. ]+$" "" summary "${summary}")
string(REGEX REPLACE "^${name}: " "" summary "${summary}")  # rsg_gateway's help starts with its name
# help2man's NAME line is "name - summary": a summary starting with a capital reads as a sentence.
string(SUBSTRING "${summary}" 0 1 first)
string(SUBSTRING "${summary}" 1 -1 rest)
string(TOLOWER "${first}" first)
set(page "${OUT}")
string(REGEX REPLACE "\\.gz$" "" page "${page}")
execute_process(COMMAND "${HELP2MAN}" --no-info --no-discard-stderr --version-string=${VERSION}
                        "--name=${first}${rest}" --section=1 --source=rsg --manual=rsg --output=${page} "${TOOL}"
                RESULT_VARIABLE status ERROR_VARIABLE error)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "help2man ${name}: ${error}")
endif()
execute_process(COMMAND gzip -9nf "${page}" RESULT_VARIABLE status)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "gzip ${page} failed")
endif()
