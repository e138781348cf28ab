#!/usr/bin/env python3
"""Man pages and bash completion for `strata`, read from the program's own `--help`, so that
they cannot drift from the options the program takes (cmake/Install.cmake runs this at build
time; `cmake --install` puts the results in share/man/man1 and share/bash-completion).

Usage: HelpPages.py STRATA OUT_DIR
Writes OUT_DIR/man1/strata.1, one OUT_DIR/man1/strata-<command>.1 per subcommand (a subcommand's
own subcommands, as `session list`, are sections of its page) and OUT_DIR/completion/strata.

It reads CLI11's help layout (2.1): a description, "Usage: ...", then the groups "Positionals:",
"Options:" and "Subcommands:" with entries indented by two spaces and descriptions in a column,
then the footer (examples and notes). Any other text is kept as footer text.
"""
import pathlib
import re
import shutil
import subprocess
import sys

GROUPS = ("Positionals", "Options", "Subcommands")
HEADINGS = {"Positionals": "ARGUMENTS", "Options": "OPTIONS", "Subcommands": "COMMANDS"}


def read_help(strata, words):
    done = subprocess.run([strata, *words, "--help"], capture_output=True, text=True, check=True)
    return done.stdout


def parse_help(text):
    """{description, usage, groups: {name: [(name, description)]}, footer: [lines]}."""
    lines = text.rstrip("\n").split("\n")
    usage_at = next(i for i, line in enumerate(lines) if line.startswith("Usage: "))
    page = {"description": " ".join(l.strip() for l in lines[:usage_at] if l.strip()),
            "usage": lines[usage_at][len("Usage: "):], "groups": {}, "footer": []}
    if not page["usage"].startswith("strata"):  # CLI11 names an unnamed program by its path
        raise SystemExit(f"HelpPages.py: the help's usage names another program: {text}")
    group = None
    for line in lines[usage_at + 1:]:
        if line.endswith(":") and line[:-1] in GROUPS:
            group = page["groups"].setdefault(line[:-1], [])
        elif group is not None and re.match(r"  \S", line):
            # An entry: its name, then the description after a run of spaces (CLI11 pads the
            # name to column 30, one space at least; a longer name puts the description on the
            # next line).
            name, _, description = line.strip().partition("  ")
            if not description and len(line) > 30 and line[29] == " ":
                name, description = line[:30], line[30:]
            name = name.strip()
            group.append([name, [description.strip()] if description.strip() else []])
        elif group is not None and group and line.startswith("   ") and line.strip():
            group[-1][1].append(line.strip())
        elif group is not None and not line.strip():
            continue
        else:
            group = None  # the footer starts at the first line that is not part of a group
            page["footer"].append(line)
    while page["footer"] and not page["footer"][0].strip():
        page["footer"].pop(0)
    return page


def roff(text):
    """Text as roff: backslashes and hyphens escaped, no line starting with a control dot."""
    text = text.replace("\\", "\\e").replace("-", "\\-")
    return "\\&" + text if text.startswith((".", "'")) else text


def sections_of(page, nested=False):
    """The page's sections; a nested subcommand's (`session list`) as subsections of its own."""
    def heading(title):
        return f".SS {title.capitalize()}" if nested else f".SH {title}"

    out = [heading("SYNOPSIS"), f".B {roff(page['usage'])}",
           heading("DESCRIPTION"), roff(page["description"])]
    for group in GROUPS:
        entries = page["groups"].get(group)
        if entries:
            out.append(heading(HEADINGS[group]))
        for name, description in entries or []:
            out += [".TP", f".B {roff(name)}"] + [roff(d) + "\n.br" for d in description]
    footer = page["footer"]
    if footer:
        examples = re.fullmatch(r"Examples?:", footer[0].strip()) is not None
        out.append(heading("EXAMPLES" if examples else "NOTES"))
        verbatim = False
        for line in footer[1:] if examples else footer:  # the heading says "Examples" already
            if not line.strip():
                out.append(".sp")
                continue
            if line.startswith("  ") != verbatim:  # indented lines are commands: kept as is
                verbatim = not verbatim
                out.append(".RS\n.nf" if verbatim else ".fi\n.RE")
            out.append(roff(line[2:] if verbatim else line))
        if verbatim:
            out.append(".fi\n.RE")
    return out


def man_page(name, summary, version, sections):
    header = ['.\\" Generated from `strata ... --help` by tools/strata/HelpPages.py.',
              f'.TH {name.upper()} 1 "" "{roff(version)}" "strata manual"',
              ".SH NAME", f"{name} \\- {roff(summary)}"]
    return "\n".join(header + sections) + "\n"


def completion_script(tree):
    """A bash completion script: each command path's options and subcommands."""
    options = "\n".join(f'        ["{path}"]="{" ".join(o)}"' for path, (o, _) in tree.items())
    commands = "\n".join(f'        ["{path}"]="{" ".join(c)}"' for path, (_, c) in tree.items()
                         if c)
    return f"""# bash completion for strata: its subcommands and each one's options. Generated from
# `strata ... --help` by tools/strata/HelpPages.py; do not edit.
_strata() {{
    # Keyed by command path ("strata session list"): its options, its subcommands.
    local -A options=(
{options}
    )
    local -A commands=(
{commands}
    )
    local path=strata cur=${{COMP_WORDS[COMP_CWORD]}} i
    for ((i = 1; i < COMP_CWORD; i++)); do
        [[ -n ${{options["$path ${{COMP_WORDS[i]}}"]+set}} ]] && path+=" ${{COMP_WORDS[i]}}"
    done
    COMPREPLY=()
    if [[ $cur == -* ]]; then
        mapfile -t COMPREPLY < <(compgen -W "${{options[$path]}}" -- "$cur")
    elif [[ -n ${{commands[$path]+set}} ]]; then
        mapfile -t COMPREPLY < <(compgen -W "${{commands[$path]}}" -- "$cur")
    fi  # else file names (complete -o default): what most arguments and option values are
}}
complete -o default -F _strata strata
"""


def option_names(page):
    names = []
    for name, _ in page["groups"].get("Options", []):
        names += [n for n in name.split(" ")[0].split(",") if n.startswith("-")]
    return names


def main():
    strata, out = sys.argv[1], pathlib.Path(sys.argv[2])
    version = subprocess.run([strata, "--version"], capture_output=True, text=True,
                             check=True).stdout.strip()
    shutil.rmtree(out / "man1", ignore_errors=True)  # no page of a removed subcommand stays
    (out / "man1").mkdir(parents=True)
    (out / "completion").mkdir(parents=True, exist_ok=True)
    top = parse_help(read_help(strata, []))
    commands = [name for name, _ in top["groups"].get("Subcommands", [])]
    tree = {"strata": (option_names(top), commands)}
    summary = top["description"].removeprefix("strata: ")
    see_also = ".SH SEE ALSO\n" + ",\n".join(f".BR strata\\-{c} (1)" for c in commands)
    (out / "man1" / "strata.1").write_text(
        man_page("strata", summary, version, sections_of(top) + [see_also]))
    for command in commands:
        page = parse_help(read_help(strata, [command]))
        nested = [name for name, _ in page["groups"].get("Subcommands", [])]
        tree[f"strata {command}"] = (option_names(page), nested)
        sections = sections_of(page)
        for sub in nested:
            subpage = parse_help(read_help(strata, [command, sub]))
            tree[f"strata {command} {sub}"] = (option_names(subpage), [])
            sections += [f'.SH "{roff(f"STRATA {command} {sub}".upper())}"']
            sections += sections_of(subpage, nested=True)
        sections.append(".SH SEE ALSO\n.BR strata (1)")
        (out / "man1" / f"strata-{command}.1").write_text(
            man_page(f"strata-{command}", page["description"], version, sections))
    (out / "completion" / "strata").write_text(completion_script(tree))


if __name__ == "__main__":
    main()
