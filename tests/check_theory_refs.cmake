# ctest script (nsp_theory_references): every "THEORY <section>" citation in the headers, tests,
# benchmarks, examples, README.md and docs/*.md names a section that docs/theory.md has.
#   cmake -DNSP_SOURCE_DIR=<repo> -P tests/check_theory_refs.cmake
# Sections are the numbers right after the hashes of docs/theory.md's headings ("## 4. Sampling",
# "### 4.1 Free flight"). A citation is THEORY followed by a number, and by more numbers joined
# with ",", "-" (a range: both ends are checked), "with" or "and": "THEORY 4.1-4.3", "THEORY 5.4
# with 5.1, 5.3". A citation may wrap onto the next comment line. "THEORY 5" needs section 5.
# A bare THEORY without a number is reported as a warning, not a failure (the placeholder
# "THEORY n.m" that explains the notation is not). -DNSP_THEORY_VERBOSE=ON
# lists every citation found.
cmake_minimum_required(VERSION 3.20)  # policies of this CMake era (while() and if() on TRUE, IN_LIST)
if(NOT DEFINED NSP_SOURCE_DIR)
    message(FATAL_ERROR "check_theory_refs.cmake needs -DNSP_SOURCE_DIR=<the nsp source directory>")
endif()
get_filename_component(root "${NSP_SOURCE_DIR}" ABSOLUTE)
set(theory "${root}/docs/theory.md")
if(NOT EXISTS "${theory}")
    message(FATAL_ERROR "nsp_theory_references: ${theory} does not exist")
endif()

# The section numbers of docs/theory.md.
set(num "[0-9]+(\\.[0-9]+)*")
file(READ "${theory}" text)
string(REGEX MATCHALL "\n#+[ \t]+${num}" headings "\n${text}")
set(sections "")
foreach(h IN LISTS headings)
    string(REGEX MATCH "${num}$" n "${h}")
    list(APPEND sections "${n}")
endforeach()
list(REMOVE_DUPLICATES sections)
if(NOT sections)
    message(FATAL_ERROR "nsp_theory_references: no numbered headings (such as '## 4. Sampling a segment') in ${theory}")
endif()
string(REPLACE ";" " " sections_text "${sections}")

file(GLOB_RECURSE files LIST_DIRECTORIES false
     "${root}/include/*.hpp" "${root}/tests/*.cpp" "${root}/tests/*.hpp" "${root}/bench/*.cpp"
     "${root}/examples/*.cpp" "${root}/examples/*.hpp")
file(GLOB docs LIST_DIRECTORIES false "${root}/docs/*.md")
list(APPEND files "${root}/README.md" ${docs})
list(REMOVE_DUPLICATES files)
list(SORT files)

# A line break with the next line's comment marker reads as one separator (@NL@ keeps the count
# of lines for the messages).
set(sep "([ \t]|@NL@)")
set(join "${sep}*(,|-|–|with|and)${sep}*")
set(citation_re "THEORY${sep}+${num}(${join}${num})*")

set(citations 0)
set(numbers 0)
set(cited_files 0)
set(errors "")
set(warnings "")
foreach(f IN LISTS files)
    if(NOT EXISTS "${f}")
        continue()
    endif()
    file(READ "${f}" content)
    string(FIND "${content}" "THEORY" any)
    if(any EQUAL -1)
        continue()
    endif()
    file(RELATIVE_PATH rel "${root}" "${f}")
    math(EXPR cited_files "${cited_files} + 1")
    string(REGEX REPLACE "[ \t]*\r?\n[ \t]*(//[/!]?|\\*+|#+|>+)?[ \t]*" "@NL@" rest "${content}")
    set(line 1)
    while(TRUE)
        string(FIND "${rest}" "THEORY" pos)
        if(pos EQUAL -1)
            break()
        endif()
        # The line of this mention: the line breaks before it.
        string(SUBSTRING "${rest}" 0 ${pos} before)
        string(LENGTH "${before}" len_before)
        string(REPLACE "@NL@" "" before_stripped "${before}")
        string(LENGTH "${before_stripped}" len_stripped)
        math(EXPR line "${line} + (${len_before} - ${len_stripped}) / 4")
        string(SUBSTRING "${rest}" ${pos} -1 rest)
        string(REGEX MATCH "^${citation_re}" cite "${rest}")
        if(cite STREQUAL "")
            # Not a citation: THEORY without a section number (a placeholder such as "THEORY n.m"
            # explaining the notation is fine).
            string(REGEX MATCH "^THEORY${sep}+(n(\\.m)*([^A-Za-z0-9]|$)|<)" placeholder "${rest}")
            string(SUBSTRING "${rest}" 6 -1 rest)
            if(NOT placeholder STREQUAL "")
                continue()
            endif()
            string(SUBSTRING "THEORY${rest}" 0 40 context)
            string(REPLACE "@NL@" " " context "${context}")
            string(APPEND warnings "\n  ${rel}:${line}: '${context}...' cites no section number")
            continue()
        endif()
        math(EXPR citations "${citations} + 1")
        string(REPLACE "@NL@" " " shown "${cite}")
        string(REGEX REPLACE "[ \t]+" " " shown "${shown}")
        if(NSP_THEORY_VERBOSE)
            message(STATUS "${rel}:${line}: ${shown}")
        endif()
        string(REGEX MATCHALL "${num}" cited "${cite}")
        foreach(n IN LISTS cited)
            math(EXPR numbers "${numbers} + 1")
            if(NOT n IN_LIST sections)
                string(APPEND errors "\n  ${rel}:${line}: '${shown}' cites section ${n}, which docs/theory.md does not have")
            endif()
        endforeach()
        # Go on after the citation, keeping the line count of the part consumed.
        string(LENGTH "${cite}" len_cite)
        string(REPLACE "@NL@" "" cite_stripped "${cite}")
        string(LENGTH "${cite_stripped}" len_cite_stripped)
        math(EXPR line "${line} + (${len_cite} - ${len_cite_stripped}) / 4")
        string(SUBSTRING "${rest}" ${len_cite} -1 rest)
    endwhile()
endforeach()

if(warnings)
    message(WARNING "nsp_theory_references: mentions of THEORY without a section number:${warnings}")
endif()
if(errors)
    message(FATAL_ERROR "nsp_theory_references: citations without a section in docs/theory.md:${errors}\n"
                        "docs/theory.md has the sections: ${sections_text}")
endif()
list(LENGTH files nfiles)
message(STATUS "nsp_theory_references: ${citations} citations (${numbers} section numbers) in ${cited_files} "
               "of ${nfiles} files all resolve; docs/theory.md has the sections: ${sections_text}")
