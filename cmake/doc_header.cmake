# nsp_doc_header(<markdown file> <name> <output header>)
# Writes the block of the markdown file marked <!-- consumer-header: <name> --> on the line before
# its ```cpp fence to <output header>, after #pragma once, the standard headers it may use and
# <nsp/nsp.hpp>, with a #line that points compiler messages at the markdown file. The docs' code a
# host copies is then the code the package test (cmake/consumer) and nsp's own tests compile.
function(nsp_doc_header doc name out)
    set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS "${doc}")
    file(READ "${doc}" text)
    string(REPLACE "\r\n" "\n" text "${text}")
    set(marker "\n<!-- consumer-header: ${name} -->\n```cpp\n")
    string(FIND "${text}" "${marker}" at)
    if(at EQUAL -1)
        message(FATAL_ERROR "${doc} has no block marked '<!-- consumer-header: ${name} -->' on the line "
                            "before a ```cpp fence")
    endif()
    string(SUBSTRING "${text}" 0 ${at} before)
    string(REGEX MATCHALL "\n" newlines "${before}")
    list(LENGTH newlines line)
    math(EXPR line "${line} + 4")  # the marker's line is line + 2 (1-based), the code starts 2 below it
    string(LENGTH "${marker}" marker_len)
    math(EXPR from "${at} + ${marker_len}")
    string(SUBSTRING "${text}" ${from} -1 tail)
    string(FIND "${tail}" "\n```" close)
    if(close EQUAL -1)
        message(FATAL_ERROR "${doc}: block '${name}': no closing ``` fence")
    endif()
    string(SUBSTRING "${tail}" 0 ${close} body)
    file(WRITE "${out}.tmp"
"// Generated from ${doc} (the block marked consumer-header: ${name}). Do not edit; edit the doc.\n"
"#pragma once\n\n#include <cstddef>\n#include <cstdint>\n#include <vector>\n\n#include <nsp/nsp.hpp>\n\n"
"#line ${line} \"${doc}\"\n${body}\n")
    configure_file("${out}.tmp" "${out}" COPYONLY)  # rewritten only when it changes
endfunction()
