# ctest script: runs one command of an example tool and checks its exit code and messages (ctest
# itself only tells zero from nonzero). The exit codes are tool.hpp's: 0, 1 (runtime failure), 2
# (usage).
# Inputs:
#   CMD           the command and its arguments, separated by '|'
#   CODE          the exit code it must return
#   ERR_REGEX     a regular expression its stderr must match
#   OUT_REGEX     (optional) one its stdout must match
#   MAKE_FILE     (optional) a regular file to create first (e.g. for "--out FILE/sub")
#   MAKE_DIR      (optional) a directory to create first (e.g. a directory named like a volume file)
#   MAKE_FULL     (optional) a path to make a symbolic link to /dev/full (every write to it fails
#                 with "no space left"); without /dev/full the test prints "SKIP: no /dev/full"
foreach(v CMD CODE ERR_REGEX)
    if(NOT DEFINED ${v})
        message(FATAL_ERROR "exit_code_test.cmake needs -D${v}=...")
    endif()
endforeach()
if(DEFINED MAKE_FILE)
    get_filename_component(dir ${MAKE_FILE} DIRECTORY)
    file(MAKE_DIRECTORY ${dir})
    file(REMOVE_RECURSE ${MAKE_FILE})
    file(WRITE ${MAKE_FILE} "a regular file\n")
endif()
if(DEFINED MAKE_DIR)
    file(REMOVE_RECURSE ${MAKE_DIR})
    file(MAKE_DIRECTORY ${MAKE_DIR})
endif()
if(DEFINED MAKE_FULL)
    if(NOT EXISTS /dev/full)
        message("SKIP: no /dev/full")
        return()
    endif()
    get_filename_component(dir ${MAKE_FULL} DIRECTORY)
    file(MAKE_DIRECTORY ${dir})
    file(REMOVE ${MAKE_FULL})
    file(CREATE_LINK /dev/full ${MAKE_FULL} SYMBOLIC)
endif()

string(REPLACE "|" ";" command "${CMD}")
execute_process(COMMAND ${command} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
string(REPLACE ";" " " shown "${command}")
if(NOT rc STREQUAL CODE)
    message(FATAL_ERROR "`${shown}` exited with ${rc}, not ${CODE}.\nstderr:\n${err}\nstdout:\n${out}")
endif()
if(NOT err MATCHES "${ERR_REGEX}")
    message(FATAL_ERROR "`${shown}`: stderr does not match '${ERR_REGEX}':\n${err}")
endif()
if(DEFINED OUT_REGEX AND NOT out MATCHES "${OUT_REGEX}")
    message(FATAL_ERROR "`${shown}`: stdout does not match '${OUT_REGEX}':\n${out}")
endif()
message(STATUS "`${shown}`: exit ${rc}, ${err}")
