"""The reproduction manuscript's generated parts: numbers, claims table, figures.

Everything the text of ``paper/reproduction.tex`` quotes comes from here, computed from the
datasets of the build (``results/paper/*.tex``), never typed:

* ``numbers.tex``: ``\\ours{id}``, ``\\paperval{id}``, ``\\verdict{id}`` for every claim,
  ``\\val{key}`` for the other numbers (counts, convergence verdicts, provenance);
  an undefined key stops LaTeX with an error instead of printing nothing;
* ``claims_table.tex``: one row per claim (long table);
* ``readings_table.tex``: the readings behind "reproduced under reading";
* ``figures.tex``: one float per figure of the config, its caption ending with its
  provenance (config, git commit, the parameters of its scenes).

``expected.json`` holds, for every macro, the text it must produce in the PDF;
``tools/check_paper.py`` compares it with ``pdftotext`` of the built PDF.
Post-processing: reads datasets only.
"""
from __future__ import annotations

import json
import math
import re
from pathlib import Path
from typing import Any, Iterable, Mapping

import numpy as np
import xarray as xr

from .. import layout
from ..analysis import distributions
from ..analysis.figure_quantities import STATED_PARAMETERS
from ..analysis.regions import REGIONS
from .verdicts import VERDICTS, Verdict, fmt

# LaTeX special characters in plain text
_TEX = {"\\": r"\textbackslash{}", "&": r"\&", "%": r"\%", "$": r"\$", "#": r"\#", "_": r"\_",
        "{": r"\{", "}": r"\}", "~": r"\textasciitilde{}", "^": r"\textasciicircum{}", "|": r"\textbar{}",
        "<": r"\textless{}", ">": r"\textgreater{}"}


def tex_escape(text: str) -> str:
    """Plain ASCII text -> LaTeX text (refuses what pdflatex could not typeset)."""
    bad = sorted({ch for ch in text if ord(ch) > 127})
    if bad:
        raise ValueError(f"non-ASCII characters {bad} in generated text {text[:60]!r}")
    return "".join(_TEX.get(ch, ch) for ch in text)


_NUMBER = re.compile(r"^(-?)(\d[\d,]*\.?\d*)(?:e([+-]?\d+))?$")


def is_number(text: str) -> bool:
    return bool(_NUMBER.match(text))


#: a hyphen that is the sign of a number inside a sentence (at its start or after a space or bracket)
_TEXT_MINUS = re.compile(r"(^|[\s(;,])-(?=\d|\.\d)")


def tex_value(text: str) -> tuple[str, str]:
    """A value as LaTeX and as the text pdftotext gives back (minus sign and times as
    the ASCII '-' and 'x' after normalize()). Numbers get a real minus sign and x10^n."""
    m = _NUMBER.match(text)
    if not m:
        return tex_escape(text), text
    sign, mant, exp = m.groups()
    tex = (r"\ensuremath{-}" if sign else "") + mant
    plain = sign + mant
    if exp is not None:
        e = int(exp)
        tex += rf"\ensuremath{{\times10^{{{e}}}}}"
        plain += f"x10{e}"
    return tex, plain


def normalize(text: str) -> str:
    """What the PDF check compares: pdftotext's output without spaces, with the minus sign
    and the times sign as ASCII, hyphenation at line ends undone, and without underscores
    (pdflatex draws \\_ as a rule, which pdftotext does not return). Hyphenation is undone first,
    on the ASCII hyphen only: a minus or plus-minus sign that ends a line is no hyphen."""
    text = re.sub(r"-\n", "", text)
    for char, ascii_ in (("\u2212", "-"), ("\u00b1", "+-"), ("\u00d7", "x"), ("\u02c6", "^"), ("\ufb01", "fi"),
                         ("\ufb02", "fl")):
        text = text.replace(char, ascii_)
    return re.sub(r"\s+", "", text).replace("_", "")


# --- captions: plain text -> LaTeX ------------------------------------------------------------
#
# Captions are written as plain ASCII text by each figure kind's caption() (and the pipeline's
# parameter list). caption_tex() typesets the notation they use and escapes everything else as
# tex_escape() does, so an unforeseen construct prints as text instead of breaking the build.
# The recognised notation (tests/test_caption_tex.py has an example of each):
#   symbols with subscripts   F_z, L_z, k_fr, k_ph, k_w, s_h, L_half, beta_ph -> F_{z}, k_{\mathrm{fr}}, ...
#                             (single-letter subscripts x, y, z, i, j, n and digits italic, others roman)
#   letter + digit            l0, l0', q0, F0 -> l_{0}, l_{0}', q_{0}, F_{0}
#   single-letter variables   s, x, y, z, g, c, f, L, R, C, F, K, N (A unless it starts a sentence)
#   EI, 2EI, 4R^2             coefficients written against their symbol
#   exponents                 R^2, x^-1, (..)^c, x^(1/2) -> R^{2}, x^{-1}, (..)^{c}, x^{1/2}
#   functions                 F(L), f(0), |F_z(s)|, ln|F_z|, sqrt(1 - R^2 w^2), sqrt 3
#   derivatives               dphi/ds, dL_z/dF, d(1/|F_z|)/ds -> \mathrm{d}\phi/\mathrm{d}s, ...
#   Greek words               pi, phi, omega, theta, ... (also with subscripts: beta_ph)
#   operators                 = + - / < > <= >= -> +- ~ -> \leq \geq \to \pm \sim (+ and - when spaced)
#   numbers                   1e-05 -> 10^{-5}, 2.5e-3 -> 2.5\times10^{-3}, 4x -> 4\times
#   units                     0.25 EI/R^2, 24 R -> a thin space between a number and its unit
#   ranges                    seeds 0-4, (a)-(c) -> en dash (text)
#   coordinate planes         x-z -> $x$--$z$
#   identifiers and files     planar_then_3d, fig8_escape, confined_rod.analysis.regions, docs/model.md -> \texttt{...}
#   quotes                    'straight', "word" -> `straight', ``word''
# A maximal run of these joined by operators, spaces or nothing (2EI) is one $...$; a run that
# is a plain number, or a panel label (a), stays text.

_GREEK = ("alpha", "beta", "gamma", "delta", "epsilon", "zeta", "eta", "theta", "kappa", "lambda", "mu", "nu",
          "xi", "pi", "rho", "sigma", "tau", "phi", "chi", "psi", "omega",
          "Gamma", "Delta", "Theta", "Lambda", "Xi", "Pi", "Sigma", "Phi", "Psi", "Omega")
_GREEK_RE = "|".join(sorted(_GREEK, key=len, reverse=True))
_SUB = r"[A-Za-z0-9]+"
_END = r"(?![A-Za-z0-9_])"                     # an atom ends where a word would go on
_RE = {name: re.compile(pattern) for name, pattern in {
    "deriv": rf"d({_GREEK_RE}|[A-Za-z](?:_{_SUB})?)/d({_GREEK_RE}|[A-Za-z]){_END}",
    "greek": rf"({_GREEK_RE})(?:_({_SUB}))?{_END}",
    "func": r"(sqrt|ln|log|exp|sin|cos|tan)(?=[(|]| (?=[A-Za-z0-9(|]))",
    "EI": rf"EI{_END}",
    "sub": rf"([A-Za-z])_({_SUB}){_END}",
    "digit": rf"([lqFfsLzk])(\d){_END}",
    "var": r"([sxyzgcfLRCFKN])(?![A-Za-z0-9_'])|(A)(?![A-Za-z0-9_']| [a-z])",
    "letter_exp": r"([A-Za-z])(?=\^)",
    "number": r"(\d+(?:\.\d+)?)(?:e([+-]?\d{1,3}))?(?![\d.]\d)",
    "times": rf"x{_END}",
    "binop": r" *(<=|>=|->|\+-|=|<|>|~|/) *| (\+|-|\*) ",
    "prefix": r"(<=|>=|->|\+-|=|<|>|~|-|\+) ?",
    "exponent": r"\^(?:(-?\d+(?:\.\d+)?|-?[A-Za-z](?![A-Za-z0-9_]))|(-?)(?=\())",
    "panel": r"\([a-h]\)(?:-\([a-h]\))?",
    "range": r"(\d+(?:\.\d+)?)-(\d+(?:\.\d+)?)(?![\w.])",
    "plane": rf"([xyz])-([xyz]){_END}",
    "path": r"(?:[A-Za-z0-9_.-]+/)+[A-Za-z0-9_.-]+\.(?:md|py|nc|yaml|yml|csv|tex|txt|pdf|png|json|smk)(?![A-Za-z0-9])",
    "ident": r"[A-Za-z][A-Za-z0-9]*(?:_[A-Za-z0-9]+)+(?:\.[A-Za-z_][A-Za-z0-9_]*)*(?![A-Za-z0-9])",
    "word": r"[A-Za-z0-9]+",
}.items()}
_OPS = {"<=": r"\leq", ">=": r"\geq", "->": r"\to", "+-": r"\pm", "~": r"\sim", "*": r"\cdot", "=": "=", "<": "<",
        ">": ">", "/": "/", "+": "+", "-": "-"}
_ITALIC_SUB = set("xyzijn0123456789")


def _sub_tex(sub: str) -> str:
    return sub if len(sub) == 1 and sub in _ITALIC_SUB or sub.isdigit() else rf"\mathrm{{{sub}}}"


def _prefix_tex(op: str) -> str:
    """An operator before its operand: -0.9, \\pm R, = 0.25."""
    return _OPS[op] if op in ("-", "+") else _OPS[op] + " "


def _number_tex(mant: str, exp: str | None) -> str:
    if exp is None:
        return mant
    e = int(exp)
    return f"10^{{{e}}}" if mant == "1" else rf"{mant}\times10^{{{e}}}"


class _Expr:
    """A parsed formula: its LaTeX and whether it is more than a plain number."""

    def __init__(self, tex: str, math: bool, end: int):
        self.tex, self.math, self.end = tex, math, end


class _CaptionParser:
    def __init__(self, text: str):
        self.s = text

    def match(self, name: str, i: int):
        return _RE[name].match(self.s, i)

    # -- formulas ---------------------------------------------------------------------------
    def atom(self, i: int, after_number: bool = False):
        """One operand at i: (tex, end, kind, strong) or None. kind: 'number', 'symbol' (may take
        an argument and a prime), 'group'."""
        s = self.s
        if i >= len(s):
            return None
        if not after_number:
            if s[i] == "(":
                inner = self.expr(i + 1, stop=")")
                if inner is not None and inner.end < len(s) and s[inner.end] == ")":
                    return "(" + inner.tex + ")", inner.end + 1, "group", True
                return None
            if s[i] == "|":
                inner = self.expr(i + 1, stop="|")
                if inner is not None and inner.end < len(s) and s[inner.end] == "|":
                    return "|" + inner.tex + "|", inner.end + 1, "group", True
                return None
            if s[i] == "d" and s.startswith("d(", i):     # d(1/|F_z|)/ds
                group = self.atom(i + 1)
                if group is not None:
                    m = re.compile(rf"/d({_GREEK_RE}|[A-Za-z]){_END}").match(s, group[1])
                    if m:
                        var = "\\" + m.group(1) if m.group(1) in _GREEK else m.group(1)
                        return rf"\mathrm{{d}}{group[0]}/\mathrm{{d}}{var}", m.end(), "symbol", True
            m = self.match("deriv", i)
            if m:
                f, v = m.groups()
                f = self._symbol(f)
                v = "\\" + v if v in _GREEK else v
                return rf"\mathrm{{d}}{f}/\mathrm{{d}}{v}", m.end(), "symbol", True
            m = self.match("number", i)
            if m:
                if not m.group(2) and self.match("times", m.end()):
                    return m.group(1) + r"\times", m.end() + 1, "number", True
                return _number_tex(*m.groups()), m.end(), "number", m.group(2) is not None
        m = self.match("func", i)
        if m:
            name = m.group(1)
            j = m.end() + (1 if s[m.end()] == " " else 0)
            arg = self.term(j)
            if arg is None:
                return None
            tex, end = arg
            if name == "sqrt":
                if tex.startswith("(") and tex.endswith(")") and self._balanced(tex[1:-1]):
                    tex = tex[1:-1]
                return rf"\sqrt{{{tex}}}", end, "group", True
            return rf"\{name}" + ("" if tex[0] in "(|" else " ") + tex, end, "group", True
        m = self.match("EI", i)
        if m:
            return "EI", m.end(), "symbol", True
        for name in ("greek", "sub", "digit"):
            m = self.match(name, i)
            if m:
                return self._symbol(m.group(0)), m.end(), "symbol", True
        m = self.match("var", i)
        if m:
            return m.group(1) or m.group(2), m.end(), "symbol", True
        m = self.match("letter_exp", i)
        if m:
            return m.group(1), m.end(), "symbol", True
        return None

    @staticmethod
    def _balanced(tex: str) -> bool:
        depth = 0
        for ch in tex:
            depth += {"(": 1, ")": -1}.get(ch, 0)
            if depth < 0:
                return False
        return depth == 0

    @staticmethod
    def _symbol(word: str) -> str:
        m = _RE["greek"].fullmatch(word)
        if m:
            base, sub = "\\" + m.group(1), m.group(2)
        elif "_" in word:
            base, sub = word.split("_", 1)
        elif len(word) == 2 and word[1].isdigit():
            base, sub = word[0], word[1]
        else:
            return word
        return base if sub is None else f"{base}_{{{_sub_tex(sub)}}}"

    def term(self, i: int, after_number: bool = False):
        """An operand with its postfixes (argument, prime, exponent): (tex, end) or None."""
        a = self.atom(i, after_number)
        if a is None:
            return None
        tex, j, kind, strong = a
        self._strong = self._strong or strong
        s = self.s
        while j < len(s):
            if kind == "symbol" and s[j] == "(":          # F(L), F_z(0)
                arg = self.atom(j)
                if arg is None or arg[2] != "group":
                    break
                tex, j = tex + arg[0], arg[1]
                continue
            if kind == "symbol" and s[j] == "'" and not s[j + 1:j + 2].isalpha():   # l0'
                tex, j = tex + "'", j + 1
                continue
            m = self.match("exponent", j)
            if m:
                if m.group(1):
                    tex, j = tex + f"^{{{m.group(1)}}}", m.end()
                else:                                       # ^(1/2), ^-(..)
                    grp = self.atom(m.end())
                    if grp is None or grp[2] != "group" or not grp[0].startswith("("):
                        break
                    tex, j = tex + f"^{{{m.group(2)}{grp[0][1:-1]}}}", grp[1]
                self._strong = True
                continue
            break
        return tex, j

    def expr(self, i: int, stop: str | None = None):
        """The longest formula starting at i (None if there is none). Inside a group (stop is
        ')' or '|') it must reach the closing character."""
        s = self.s
        saved = getattr(self, "_strong", False)
        self._strong = False
        parts: list[str] = []
        m = self.match("prefix", i)
        if m and (m.group(1) in _OPS):
            first = self.term(m.end())
            if first is None:
                if stop is not None or m.group(1) in ("-", "+"):
                    self._strong = saved
                    return None
                self._strong = saved
                return _Expr(_OPS[m.group(1)], True, i + len(m.group(1)))
            parts += [_prefix_tex(m.group(1)), first[0]]
            self._strong = True
            j = first[1]
        else:
            first = self.term(i)
            if first is None:
                self._strong = saved
                return None
            parts.append(first[0])
            j = first[1]
        last_number = self._is_number(parts[-1])
        n_terms = 1
        while j < len(s):
            if stop is not None and s[j] == stop:
                break
            m = self.match("binop", j)
            if m:
                op = m.group(1) or m.group(2)
                nxt = self.match("prefix", m.end())
                k = m.end()
                unary = ""
                if nxt and nxt.group(1) in ("-", "+-") and op != "/" and not nxt.group(0).endswith(" "):
                    unary, k = _prefix_tex(nxt.group(1)), nxt.end()
                t = self.term(k)
                if t is None:
                    break
                parts += [f" {_OPS[op]} " if op != "/" else "/", unary + t[0]]
                self._strong = True
                j, n_terms = t[1], n_terms + 1
                last_number = self._is_number(t[0]) and not unary
                continue
            if last_number:                                # 2EI, 4R^2
                t = self.term(j, after_number=True)
                if t is not None:
                    parts.append(t[0])
                    self._strong = True
                    j, n_terms, last_number = t[1], n_terms + 1, False
                    continue
            if s[j] == " ":                                 # k_fr R L, 0.25 EI/R^2
                k = j + 1
                t = self.term(k) if self._may_follow(k) else None
                if t is not None:
                    parts += [r"\,", t[0]]
                    self._strong = True
                    j, n_terms, last_number = t[1], n_terms + 1, self._is_number(t[0])
                    continue
            break
        if stop is None and j < len(s) and re.match(r"[A-Za-z0-9_]", s[j]):
            self._strong = saved                # a formula cannot end inside a word (919d2e5...)
            return None
        strong = self._strong
        self._strong = saved
        return _Expr("".join(parts), strong, j)

    def _may_follow(self, k: int) -> bool:
        """After a space, an operand may follow unless it opens a text bracket or is a panel label."""
        return k < len(self.s) and not self.match("panel", k)

    @staticmethod
    def _is_number(tex: str) -> bool:
        return bool(re.fullmatch(r"\d+(?:\.\d+)?", tex))

    # -- the caption ----------------------------------------------------------------------------
    def convert(self) -> str:
        s, out, i = self.s, [], 0
        while i < len(s):
            prev = s[i - 1] if i else " "
            at_word_start = not (prev.isalnum() or prev in "_'.")
            m = self.match("panel", i)
            if m:
                out.append(tex_escape(m.group(0)).replace(")-(", ")--("))
                i = m.end()
                continue
            if at_word_start:
                m = self.match("path", i) or self.match("ident", i)
                if m:                                   # unless it is a symbol: k_fr, beta_ph, dL_z/dF
                    self._strong = False
                    e = self.expr(i)
                    if e is None or not e.math or e.end < m.end():
                        out.append(r"\texttt{" + tex_escape(m.group(0)) + "}")
                        i = m.end()
                        continue
                m = self.match("range", i)
                if m:
                    out.append(f"{m.group(1)}--{m.group(2)}")
                    i = m.end()
                    continue
                m = self.match("plane", i)
                if m:
                    out.append(f"${m.group(1)}$--${m.group(2)}$")
                    i = m.end()
                    continue
                self._strong = False
                e = self.expr(i)
                if e is not None and e.end > i:
                    out.append(f"${e.tex}$" if e.math else tex_escape(s[i:e.end]))
                    i = e.end
                    continue
                if s[i] == "'" and i + 1 < len(s) and not s[i + 1].isspace():
                    out.append("`")
                    i += 1
                    continue
            if s[i] == '"':
                out.append("``" if at_word_start else "''")
                i += 1
                continue
            m = self.match("word", i)
            j = m.end() if m else i + 1
            out.append(tex_escape(s[i:j]))
            i = j
        return "".join(out)


def caption_tex(text: str) -> str:
    """A plain-text caption as LaTeX: its formulas in math mode, everything else escaped as by
    tex_escape (refuses non-ASCII text like tex_escape)."""
    tex_escape(text)                            # the same refusal of non-ASCII characters
    return _CaptionParser(text).convert()


def pm_tex(text: str) -> tuple[str, str]:
    """A 'value +- error' of pm() as LaTeX, with a real plus-minus sign, and as the plain text
    pdftotext gives back after normalize() ('0.961+-0.017')."""
    (t, p), (t2, p2) = (tex_value(x) for x in text.split(" +- "))
    return rf"{t}\ensuremath{{\pm}}{t2}", f"{p}+-{p2}"


def pm(value: float, error: float, sign: bool = False) -> str:
    """'value +- error' rounded together: the error to two significant digits, the value to the
    same decimal place ('0.1003 +- 0.0051', '112 +- 25', '+1.2 +- 0.83'); sign: a leading + on
    positive values (shifts). An error below 1e-4 of the value is given as a bound
    ('0.2888 +- <0.0001')."""
    if not (error > 0 and math.isfinite(error)):
        return format(value, "+.3g" if sign else ".3g")
    if value != 0 and error < 1e-4 * abs(value):
        # an error below the fourth significant digit: the value to four digits, the error as a bound
        unit = 10.0 ** (math.floor(math.log10(abs(value))) - 3)
        return f"{value:{'+' if sign else ''}.4g} +- <{unit:g}"
    decimals = max(0, 1 - int(math.floor(math.log10(error))))
    return f"{value:{'+' if sign else ''}.{decimals}f} +- {error:.{decimals}f}"


def _key(name: str) -> str:
    if not re.fullmatch(r"[A-Za-z0-9_.:-]+", name):
        raise ValueError(f"macro key {name!r}: letters, digits, _ . : - only")
    return name


class Macros:
    """Generated macros: key -> (LaTeX, expected plain text)."""

    def __init__(self):
        self.items: dict[str, tuple[str, str, str]] = {}
        self.raw: list[str] = []      # further definitions (tables, figure references)

    def add(self, family: str, key: str, text: str) -> None:
        tex, plain = tex_value(str(text))
        self.items[f"{family}@{_key(key)}"] = (family, tex, plain)

    def add_text(self, family: str, key: str, text: str) -> None:
        """A sentence (e.g. a verdict with its numbers): as add, with every ' +- ' typeset as a
        plus-minus sign and the minus of a negative number in it as a minus sign."""
        tex, plain = tex_value(str(text))
        tex = _TEXT_MINUS.sub(r"\1\\ensuremath{-}", tex.replace(" +- ", r" \ensuremath{\pm} "))
        self.items[f"{family}@{_key(key)}"] = (family, tex, plain)

    def add_list(self, family: str, key: str, values: list[tuple[float, float]], spec: str = ".3g") -> None:
        """A list of values mean +- s.d. (no s.d. where it is 0), typeset with a real plus-minus
        sign; pdftotext gives it back as the +- of normalize()."""
        tex, plain = [], []
        for mean, sd in values:
            t, p = tex_value(format(mean, spec))
            if sd > 0:          # the value rounded with its error (pm)
                t, p = pm_tex(pm(mean, sd))
            tex.append(t)
            plain.append(p)
        self.items[f"{family}@{_key(key)}"] = (family, ", ".join(tex) or "none", ", ".join(plain) or "none")

    def tex(self) -> str:
        lines = ["% GENERATED by confined_rod.claims.manuscript from the datasets of this build. Do not edit.",
                 r"\newcommand{\crget}[2]{\ifcsname cr@#1@#2\endcsname\csname cr@#1@#2\endcsname"
                 r"\else\errmessage{generated value #1 '#2' is not defined by this build}\fi}",
                 r"\newcommand{\ours}[1]{\crget{ours}{#1}}",
                 r"\newcommand{\paperval}[1]{\crget{paper}{#1}}",
                 r"\newcommand{\verdict}[1]{\crget{verdict}{#1}}",
                 r"\newcommand{\val}[1]{\crget{val}{#1}}"]
        for name, (family, tex, _) in sorted(self.items.items()):
            key = name.split("@", 1)[1]
            lines.append(rf"\expandafter\def\csname cr@{family}@{key}\endcsname{{{tex}}}")
        return "\n".join(lines + self.raw) + "\n"

    def expected(self) -> dict[str, str]:
        return {name: plain for name, (_, _, plain) in self.items.items()}


def claim_macros(verdicts: Iterable[Verdict], macros: Macros) -> None:
    verdicts = list(verdicts)
    for v in verdicts:
        if " +- " in ours_text(v):
            macros.add_list("ours", v.id, [(v.ours_value, v.ours_error)])
        else:
            macros.add("ours", v.id, v.ours)
        macros.add("paper", v.id, v.paper)
        # the part that holds in brackets; what leaves an inconclusive claim undecided after a comma
        macros.add_text("verdict", v.id, v.verdict + ((f", {v.part}" if v.verdict == "inconclusive" else f" ({v.part})")
                                                      if v.part else ""))
    from .verdicts import ours_only

    # the paper's claims are counted apart from the findings of our own (where: "our finding")
    paper_claims = [v for v in verdicts if not ours_only(v)]
    macros.add("val", "n_claims", str(len(paper_claims)))
    macros.add("val", "n_own_claims", str(len(verdicts) - len(paper_claims)))
    for verdict in VERDICTS:
        macros.add("val", "n_" + verdict.replace(" ", "_"), str(sum(v.verdict == verdict for v in paper_claims)))


def finding_macros(verdicts: Iterable[Verdict], titles: Mapping[str, str], macros: Macros) -> None:
    """The independent findings about the paper's claims (claims that test one discrepancy share
    one): their number by verdict (\\val{n_findings_refuted}, ...) and the titled ones by verdict
    as text (\\val{findings_refuted}: the sentences of the abstract come from the verdicts); the
    findings of our own apart (\\val{n_own_findings}, ..._reproduced, \\val{own_findings_open})."""
    from .verdicts import split_findings

    found, own = split_findings(list(verdicts))
    macros.add("val", "n_findings", str(len(found)))
    for verdict in VERDICTS:
        key = verdict.replace(" ", "_")
        macros.add("val", "n_findings_" + key, str(sum(f[0] == verdict for f in found.values())))
        named = [titles[n] for n, (v, _) in found.items() if v == verdict and n in titles]
        macros.add("val", "findings_" + key, "; ".join(named) if named else "none")
    macros.add("val", "n_own_findings", str(len(own)))
    macros.add("val", "n_own_findings_reproduced", str(sum(f[0] == "reproduced" for f in own.values())))
    macros.add("val", "own_findings_open", "; ".join(f"{titles.get(n, n)} ({f[0]})" for n, f in own.items()
                                                     if f[0] != "reproduced") or "none")


#: longest convergence verdict in the table (a paired ladder's lists every observable's numbers)
STATUS_CHARS = 130
SCENE_ATTRS = STATED_PARAMETERS     # the numbers among them: \val{<figure>.<parameter>}


def protocol_macros(name: str, ds: xr.Dataset, macros: Macros) -> None:
    """\\val{<figure>.<variant>.fraction} (mean +- s.d. of F(L)/F(0)), .lower_length, .decay_ratio,
    .tip_length_range ('6 to 168': over the seeds), .tip_length_median, .tip_length_seeds (and so for
    .lower_length_...),
    .n_reversals, \\val{<figure>.ramp_change} (the finest ramp step's paired change of F(L) over the seeds
    that keep their final state, %; only with two or more of them), .ramp_state_changes (the seeds that
    changed it) and .ramp_mean_change (the change of the ensemble mean, %)."""
    two = ("fraction", "decay_ratio", "torque_friction_ratio", "pitch_w0_ratio", "K_ratio", "K_ratio_from_torque",
           "lower_torque_ratio", "lower_azimuthal_share", "lower_utilisation", "lower_stuck_share")
    for i, v in enumerate(ds.variant.values):
        # the region lengths differ in structure between seeds (a tip of 6 R or of 170 R): their
        # distribution, not a mean over structures
        for key in ("lower_length", "tip_length"):
            if f"{key}_member" in ds:
                x = np.sort(ds[f"{key}_member"].values[i][ds["has_member"].values[i] == 1])
                if x.size:
                    same = f"{x[0]:.3g}" == f"{x[-1]:.3g}"
                    macros.add("val", f"{name}.{v}.{key}_range", f"{x[0]:.3g}" + ("" if same else f" to {x[-1]:.3g}"))
                    macros.add("val", f"{name}.{v}.{key}_median", f"{float(np.median(x)):.3g}")
                    macros.add("val", f"{name}.{v}.{key}_seeds", str(x.size))
        for key in ("lower_length", "tip_length", "n_reversals", "lower_torque", "bulk_torque_max") + two:
            if f"{key}_mean" not in ds:
                continue
            value = [(float(ds[f"{key}_mean"].values[i]), float(ds[f"{key}_std"].values[i]))]
            macros.add_list("val", f"{name}.{v}.{key}", value, ".2f" if key in two else ".3g")
    for key in ("formation_settled_quarter", "formation_settled_end"):
        if key in ds.attrs:
            macros.add("val", f"{name}.{key}", f"{float(ds.attrs[key]):.2g}")
    if "t" in ds.coords and "formation_F_abs" in ds:
        macros.add("val", f"{name}.formation_final", f"{float(ds['t'].values[-1]):.2g}")
    if "torque_closure_member" in ds:
        free = (ds["variant_ends"].values == "free")[:, None] & (ds["has_member"].values == 1)
        worst = float(ds["torque_closure_member"].values[free].max()) if free.any() else 0.0
        macros.add("val", f"{name}.torque_closure", f"{worst:.1e}")
    if "ramp_ladder_paired_change" in ds.attrs:
        change = np.atleast_1d(ds.attrs["ramp_ladder_paired_change"])[-1]
        sem = np.atleast_1d(ds.attrs["ramp_ladder_paired_sem"])[-1]
        steps = np.atleast_1d(ds.attrs["ramp_ladder_steps"])[-2:]
        kept = int(np.atleast_1d(ds.attrs["ramp_ladder_same_state"])[-1])
        if kept >= 2:
            macros.add_list("val", f"{name}.ramp_change", [(100 * float(change), 100 * float(sem))], ".2f")
        macros.add("val", f"{name}.ramp_steps", f"{steps[0]:g} to {steps[1]:g}")
        moved = int(np.atleast_1d(ds.attrs["ramp_ladder_state_changes"])[-1])
        macros.add("val", f"{name}.ramp_state_changes", f"{moved} of {moved + kept}")
        macros.add("val", f"{name}.ramp_mean_change",
                   f"{100 * float(np.atleast_1d(ds.attrs['ramp_ladder_mean_change'])[-1]):+.1f}")


def escape_macros(name: str, ds: xr.Dataset, macros: Macros) -> None:
    """\\val{<figure>.event_max_outside_radius}, .event_final_outside_radius and
    .event_escape_radius (in R) of the constructed event of an escape figure."""
    for key in ("event_max_outside_radius", "event_final_outside_radius", "event_escape_radius"):
        macros.add("val", f"{name}.{key}", f"{float(ds.attrs[key]):.3g}")


def printed_fits_macros(claims: Iterable[Mapping], datasets: Mapping[str, xr.Dataset], macros: Macros) -> None:
    """\\printedfitstable: per panel with a printed fit (rows) and per reading of the paper's
    numerics its claim tests (columns: the paper's protocol, then the claim's `readings`), whether
    the printed curve describes our profile, as the claim decides it (measures.force_decay.printed_panel,
    at the claim's max_rms): over both windows, the bulk only, or not; our F(L)/F(0) against the
    printed f(L)/load; and from which s on the curve stays within the tolerance. Empty where no
    claim of the config tests a printed curve on a built figure."""
    from .measures.force_decay import printed_panel

    rows, heads, tol = [], None, None
    for c in claims:
        t = c["test"]
        if t.get("name") != "printed_curves" or t["figure"] not in datasets:
            continue
        tol = float(t["max_rms"])
        columns = {"the paper's protocol": t["figure"], **(t.get("readings") or {})}
        heads = heads or list(columns)
        main = datasets[t["figure"]]
        for i in range(main.sizes["panel"]):
            if not int(main.has_paper_fit.values[i]):
                continue
            fig_name = f"Fig.~{main.attrs['paper_figure']}" if "paper_figure" in main.attrs else \
                tex_escape(t["figure"])
            cells = [rf"{fig_name} {tex_escape(str(printed_panel(main, i, tol)['label']))}"]
            for head in heads:
                ds = datasets.get(columns.get(head, ""))
                if ds is None or i >= ds.sizes["panel"] or not int(ds.has_paper_fit.values[i]):
                    cells.append("not built")
                    continue
                r = printed_panel(ds, i, tol)
                cells.append(tex_escape(r["answer"]) + rf"; {tex_value(format(r['fraction'], '.3g'))[0]} against "
                             rf"{tex_value(format(r['by_load'], '.3g'))[0]}"
                             + (rf"; from $s = {r['start']:.0f}\,R$" if r["start"] is not None else ""))
            rows.append(" & ".join(cells) + r" \\")
    table = ""
    if rows:
        col = r">{\raggedright\arraybackslash}p"
        table = (r"\begin{table*}[t]\caption{The printed fits of Figs.~4 and 7 against our profiles, per panel "
                 r"(rows) and per reading of what the paper leaves open (columns): whether the printed curve "
                 rf"describes ours, its $|\ln(f/|F_z|)|$ within {tol:g} in rms over the whole wall-contact stretch "
                 r"and over the bulk helix and in the transmitted fraction (described; over the bulk only; not); "
                 r"our $F(L)/F(0)$ (mean over the seeds) against the printed $f(L)/|F_z(0)|$, the curve at the "
                 r"support over the load (the printed curves' own $f(0)$ is not always the load; over it the "
                 r"fraction is in the claims' notes); and from which $s$ on the printed curve stays within the "
                 r"tolerance of ours to the end of the stretch. Where a panel has seeds, the rms is the mean over "
                 r"them of each seed's and the fraction the mean over them; that $s$ is of the shown member "
                 r"(lowest seed).}\label{tab:printed}" "\n" r"\small" "\n"
                 rf"\begin{{tabular}}{{@{{}}{col}{{0.1\linewidth}}" + "".join(
                     rf"{col}{{{0.88 / len(heads):.3f}\linewidth}}" for _ in heads) + r"@{}}\hline" "\n"
                 + "panel & " + " & ".join(caption_tex(h) for h in heads) + r" \\ \hline" "\n"
                 + "\n".join(rows) + "\n" r"\hline\end{tabular}\end{table*}")
    macros.raw.append(r"\newcommand{\printedfitstable}{" + table + "}")


def local_law_macros(name: str, ds: xr.Dataset, macros: Macros) -> None:
    """\\val{<figure>.decay_ratio}: the bulk decay rates over k_fr R/(4EI) of a figure's panels or
    lengths (ensemble means where there are seeds), as a list, each +- the larger of the seed
    spread and the window effect (as in the claims); .decay_ratio_rods ('0.80 to 1.06') and
    .decay_ratio_n_rods: the single rods' range and number."""
    if "decay_ratio" not in ds:
        return
    ok = ds["has_bulk"].values == 1
    if "bulk_decay_rate_mean" in ds:
        # the uncertainty the claims use: the larger of the seed spread and the window effect
        r = ds["bulk_decay_rate_mean"].values / ds["decay_rate_model"].values
        sd = np.maximum(ds["bulk_decay_rate_std"].values, ds["bulk_decay_rate_err"].values) / \
            ds["decay_rate_model"].values
    else:
        r, sd = ds["decay_ratio"].values, ds["bulk_decay_rate_err"].values / ds["decay_rate_model"].values
    macros.add_list("val", f"{name}.decay_ratio", [(float(a), float(b)) for a, b, k in zip(r, sd, ok) if k], ".2f")
    # the single rods behind the means (the one run of a panel without seeds): their range and number
    if "bulk_decay_rate_member" in ds:
        rods = (ds["bulk_decay_rate_member"].values / ds["decay_rate_model"].values[:, None])[
            (ds["has_bulk_member"].values == 1) & ok[:, None]]
    else:
        rods = np.asarray(ds["decay_ratio"].values)[ok]
    macros.add("val", f"{name}.decay_ratio_rods", f"{rods.min():.2f} to {rods.max():.2f}" if rods.size else "none")
    macros.add("val", f"{name}.decay_ratio_n_rods", str(rods.size))


def dataset_macros(datasets: Mapping[str, xr.Dataset], macros: Macros) -> None:
    """Numbers the text quotes beyond the claims: the parameters every dataset's scenes
    share (\\val{<figure>.<parameter>}), the convergence table (verdicts and distances of
    the publication settings), the build's git commits."""
    rows = []
    # the text's generic names for the l0 ladders, defined by the ladders below if the config has them
    macros.add("val", "l0_ladder.pitch_theory", "not measured")
    for region in (*REGIONS, "total", "seeds"):
        macros.add("val", f"l0_ladder.region.{region}", "not measured")
    for key in ("F_shifts", "decay_shifts", "lower_friction_use", "F_bound", "verdict"):
        macros.add("val", f"l0_ladder.{key}", "not measured")
    for name, ds in sorted(datasets.items()):
        for attr in SCENE_ATTRS:                # the parameters its scenes share, e.g. \val{fig7_tiny_force.load}
            value = np.asarray(ds.attrs.get(attr, [])).ravel()
            if value.size == 1 and np.issubdtype(value.dtype, np.number):
                macros.add("val", f"{name}.{attr}", fmt(float(value[0])))
        if ds.attrs.get("kind") == "protocol_comparison":
            protocol_macros(name, ds, macros)
        if ds.attrs.get("kind") in ("force_profile", "transmitted_force"):
            local_law_macros(name, ds, macros)
        if ds.attrs.get("kind") == "escape":
            escape_macros(name, ds, macros)
        if ds.attrs.get("kind") != "convergence":
            continue
        a = ds.attrs
        macros.add("val", f"{name}.status", str(a["status"]))
        macros.add("val", f"{name}.publication_value", fmt(float(a["publication_value"])))
        macros.add_text("val", f"{name}.verdict", short_status(str(a["status"])))
        if "quantity" in ds.coords:
            ensemble_ladder_macros(name, ds, macros)
        macros.add("val", f"{name}.distance_percent", format(100 * float(a.get("worst_distance", 0.0)), ".2g"))
        # a frictionless l0 ladder: its pitch against the discrete chain's helix (theory.discrete_helix),
        # also as \val{l0_ladder.pitch_theory} for the text, whatever the config names the ladder
        pitch_theory = (format(100 * float(a["pitch_theory_deviation"]), ".2g") + " %"
                        if "pitch_theory_deviation" in a else "not measured")
        macros.add("val", f"{name}.pitch_theory", pitch_theory)
        if "pitch_theory_deviation" in a and str(a["parameter"]) == "l0":
            macros.add("val", "l0_ladder.pitch_theory", pitch_theory)
        cells = [tex_escape(name), tex_escape(str(a["parameter"]))]
        cells += [tex_value(fmt(float(x)))[0] for x in (a["L"], a["load"], a["k_fr"], a["publication_value"])]
        tol = tex_value(fmt(100 * float(a["tolerance"])))[0]
        if "distribution_tolerance" in a:       # an ensemble ladder: the relation's / the final states'
            final = [100 * float(a["distribution_tolerance"])]
            if str(a.get("serves", "none")) != "none" and "cmp_compared_tolerance" in ds:
                # the tolerances the final states were decided against (a served figure's error where larger)
                from ..analysis.figures.convergence import RELATION_KEYS
                codes = ds["cmp_verdict_code"].values
                states = np.array([str(k) not in RELATION_KEYS for k in ds["quantity"].values])
                used = ds["cmp_compared_tolerance"].values[(codes >= 1) & (codes <= 3) & states[None, :]]
                final = sorted({float(format(100 * float(x), ".2g")) for x in used}) or final
            tol += "/" + tex_value(fmt(final[0]))[0]
            if final[-1] != final[0]:
                tol += "--" + tex_value(fmt(final[-1]))[0]
            if str(a.get("serves", "none")) != "none":      # or half the served figures' error (caption)
                tol += r"$^\ast$"
        cells.append(tol)
        cells.append(rf"\val{{{name}.distance_percent}}; \val{{{name}.verdict}}")
        rows.append(" & ".join(cells) + r" \\")
    table = ""
    if rows:
        table = (r"\begin{table*}[t]\caption{Convergence checks of the numerical settings (rule "
                 r"\texttt{convergence\_check}): each ladder varies one parameter about its publication value; the "
                 r"column `off' gives, for single runs, the worst distance of the publication value from the "
                 r"limit over $|F_z(L)|$, $L_z$ and the pitch (Richardson's extrapolation, or the finest rung "
                 r"where its differences are already below a tenth of the tolerance); for seed ensembles the "
                 r"largest shift of "
                 r"the publication rung's mean from a finer rung over every deciding quantity (the lateral balance "
                 r"of the helix, tolerance before the slash, and the final states with the ratios to the "
                 r"torque-free helix, after it), which is not a distance from a limit. In the checks, a shift is given $\pm$ its "
                 r"standard error and decided by its 95\,\% bound with Student's factor for the paired seeds; the "
                 r"Anderson--Darling $p$ of the checks is scipy's, clipped to 0.001--0.25. $^\ast$: the ladder "
                 r"vouches "
                 r"for figures of a few seeds (its \texttt{serves}) and decides on the quantities they report, "
                 r"each held to the larger of the ladder's distribution tolerance and half the 95\,\% error of "
                 r"the figure's mean; after the slash the range of tolerances so used (Sec.~``Convergence "
                 r"checks'' of the documentation). A verdict cut short is given in "
                 r"full in "
                 rf"\texttt{{{layout.CHECKS}}}.}}\label{{tab:convergence}}" "\n" r"\small" "\n"
                 r"\begin{tabular}{@{}lllllllp{0.36\linewidth}@{}}\hline" "\n"
                 r"ladder & parameter & $L/R$ & load & $k_{fr}$ & value & tol.~(\%) & off (\%), verdict \\"
                 r" \hline" "\n" + "\n".join(rows)
                 + "\n" r"\hline\end{tabular}\end{table*}")
    macros.raw.append(r"\newcommand{\convergencetable}{" + table + "}")
    commits = sorted({str(ds.attrs.get("git_commit", "unknown")) for ds in datasets.values()})
    macros.add("val", "git_commit", ", ".join(c[:12] for c in commits))


def study_macros(paths: Iterable[str], macros: Macros) -> None:
    """The studies outside the build whose files the manuscript cites (benchmarks/results/
    study_<name>.json): \val{study.<name>.seeds}, the seeds that reached equilibrium on every
    rung of the study (its paired ensemble), or the seed count it states; and the summary texts
    it writes under "macros" (\val{study.<name>.<key>})."""
    for path in sorted(paths):
        name = Path(path).stem.removeprefix("study_")
        data = json.loads(Path(path).read_text())
        runs = data.get("runs")
        if isinstance(runs, dict) and runs and all(isinstance(r, dict) for r in runs.values()):
            done = [{seed for seed, run in rung.items() if isinstance(run, dict) and run.get("converged", True)}
                    for rung in runs.values()]
            macros.add("val", f"study.{name}.seeds", str(len(set.intersection(*done))))
        elif isinstance(data.get("seeds"), int):
            macros.add("val", f"study.{name}.seeds", str(data["seeds"]))
        # the summary sentences a study writes for the manuscript: \val{study.<name>.<key>}
        for key, text in (data.get("macros") or {}).items():
            macros.add_text("val", f"study.{name}.{key}", str(text))


def _percent(x: float) -> str:
    """'2.7 %', '30 %', '140 %': two significant digits, no exponent."""
    return (format(x, ".2g") if abs(x) < 100 else format(x, ".0f")) + " %"


def budget_macros(ds: xr.Dataset | None, macros: Macros) -> None:
    """The error budget (analysis.error_budget): \\errorbudgettable, one row per headline number
    with its statistical and numerical 95 % errors and what limits it; \\val{budget.<limit>} the
    count of numbers each limits (statistics, numerics, unknown), and per headline
    \\val{budget.<headline>.stat}, \\val{budget.<headline>.bias} ('1.2 %'). Empty without a budget."""
    from ..analysis import error_budget

    rows = error_budget.rows(ds) if ds is not None else []
    deterministic = False
    for limit in error_budget.LIMITED_BY:
        macros.add("val", f"budget.{limit}", str(sum(r["limited_by"] == limit for r in rows)))
    macros.add("val", "budget.numbers", str(len(rows)))
    # what is unknown: the statistical error (a single frictional run) or every bias term
    unknown = [r for r in rows if r["limited_by"] == "unknown"]
    macros.add("val", "budget.unknown_stat", str(sum(r["stat_95_percent"] is None for r in unknown)))
    macros.add("val", "budget.unknown_bias", str(sum(r["stat_95_percent"] is not None and not r["measured"]
                                                     for r in unknown)))
    # a bias known only from below (a failing ladder) that stays under the statistical error
    macros.add("val", "budget.unknown_lower", str(sum(r["stat_95_percent"] is not None and bool(r["measured"])
                                                      for r in unknown)))
    lines = []
    for r in rows:
        stat = "not measured" if r["stat_95_percent"] is None else _percent(r["stat_95_percent"])
        bias = _percent(r["bias_95_percent"]) if r["measured"] else "not measured"
        if r["measured"] and r["lower_bound"]:
            bias = "at least " + bias       # a term from a failing ladder (error_budget: bias_lower_bound)
        macros.add("val", f"budget.{r['headline']}.stat", stat)
        macros.add("val", f"budget.{r['headline']}.bias", bias)
        if r["stat_95_percent"] == 0.0 and r["n_seeds"] == 1:
            stat, deterministic = "none*", True     # one frictionless run: a unique equilibrium
        missing = f"; not measured: {r['not_measured']}" if r["not_measured"] else ""
        largest = "" if r["largest_bias"] == "none measured" else r["largest_bias"]
        term = re.sub(r" -(?=\d)", r" \\ensuremath{-}", tex_escape(largest)).replace(" +- ", r" \ensuremath{\pm} ")
        if largest and r["largest_transferred"] == "yes":
            term += r"\textsuperscript{\dag}"
        if largest and r["largest_lower_bound"] == "yes":
            term += r"\textsuperscript{\ddag}"
        cell_bias = tex_value(bias)[0] if not bias.startswith("at least ") else \
            r"$\geq$\," + tex_value(bias.removeprefix("at least "))[0]
        cells = [tex_escape(r["figure"]), r"\raggedright " + budget_label_tex(r["label"]),
                 tex_value(format(r["value"], ".3g"))[0], str(r["n_seeds"]), tex_value(stat)[0], cell_bias,
                 r"\raggedright " + (term + tex_escape(missing)).strip("; "), tex_escape(r["limited_by"])]
        lines.append(" & ".join(cells) + r" \\")
    table = ""
    if lines:
        table = (r"\begin{table*}[p]\caption{Error budget of the headline numbers (rule \texttt{error\_budget}, "
                 rf"\texttt{{{tex_escape(layout.ERROR_BUDGET_CSV)}}}): the statistical error is the 95\,\% "
                 r"half-width $t\,\sigma$ of the mean over $n$ seeds, $\sigma$ its standard error and $t$ Student's "
                 r"quantile for $n-1$ degrees of freedom (4.3 for $n = 3$, 2.8 for $n = 5$; a share of seeds: its "
                 r"Wilson interval); the numerical bias is the 95\,\% bound $\sum_p|\delta_p| + t\,(\sum_p "
                 r"\sigma_p^2)^{1/2}$ over the numerical parameters $p$ (a bias is not random: the magnitudes add, "
                 r"their measurement errors in quadrature, $t$ the largest of their Student's quantiles), "
                 r"$\delta_p \pm \sigma_p$ the first-order distance of the publication rung's mean from the "
                 r"limit: its shift from the finest rung of the ladder over $p$ (Table~\ref{tab:convergence}) "
                 r"times $1/(1 - h_{\rm fine}/h_{\rm pub})$" + _limit_factors_tex(ds) + ", "
                 r"or for a threshold half its bisection bracket and the discretisation of the discrete chain's Euler "
                 r"load (and, where the rod was bisected again at a stiffer bond, the shift from it). The largest "
                 r"term is given with its standard error; \dag: measured at another rod (length, friction or load; "
                 r"the ladder's rod is in the table's CSV) and transferred to the number's, the decay-rate part of a "
                 r"transmitted force's shift carried to its rod's bulk and the rest as a relative shift "
                 r"(the CSV's source column says which); \ddag\ and $\geq$: read from a ladder that fails on the "
                 r"number's quantity (no asymptotic range), so the first-order term and the number's bound are lower "
                 r"bounds, and a number whose lower bound stays under its statistical error is limited by what is "
                 r"unknown. The larger of the two errors limits the number; a number "
                 r"with no bias term "
                 r"measured is limited by what is unknown."
                 + (r" none*: one frictionless run, whose equilibrium is unique, so no seed spread." if deterministic
                    else "") + r"}\label{tab:budget}" "\n" r"\scriptsize" "\n"
                 r"\begin{tabular}{@{}lp{0.27\linewidth}llllp{0.22\linewidth}l@{}}\hline" "\n"
                 r"figure & number & value & $n$ & statistics & numerics & largest bias term & limited by \\"
                 r" \hline" "\n" + "\n".join(lines) + "\n" r"\hline\end{tabular}\end{table*}")
    macros.raw.append(r"\newcommand{\errorbudgettable}{" + table + "}")


def _limit_factors_tex(ds: xr.Dataset | None) -> str:
    """' (l0 1.14, k_ph 1.11, ..., tol 1.00-1.11, ramp_steps 2; an overestimate where the order is
    higher)': per numerical parameter, the factor or range of factors 1/(1 - h_fine/h) the budget
    applied (analysis.error_budget, bias_limit_factor; a number at coarser numerics reads a
    coarser rung, with a factor nearer 1)."""
    from ..analysis import error_budget

    if ds is None or "bias_limit_factor" not in ds:
        return ""
    params = [str(p) for p in ds["budget_parameter"].values]
    by: dict[str, list[float]] = {}
    for i in range(ds.sizes["headline"]):
        for p, name in enumerate(params):
            if ds["has_bias"].values[i, p] and name in error_budget.LADDER_PARAMETERS:
                by.setdefault(name, []).append(float(ds["bias_limit_factor"].values[i, p]))
    if not by:
        return ""
    parts = []
    for name in sorted(by, key=params.index):
        lo, hi = min(by[name]), max(by[name])
        span = f"{lo:.3g}" if f"{lo:.3g}" == f"{hi:.3g}" else f"{lo:.3g}--{hi:.3g}"
        parts.append(f"{tex_escape(name)} {span}")
    return " (" + ", ".join(parts) + "; an overestimate where the order is higher)"


#: the plain-text units and symbols of the budget's labels (analysis.figures.*.headlines), as LaTeX
_LABEL_TEX = {"pi^2 EI/L^2": r"$\pi^2 EI/L^2$", "EI/R^2": r"$EI/R^2$", "k_fr R/4EI": r"$k_{\rm fr}R/4EI$",
              "F(L)/F0": r"$F(L)/F_0$", "L/R": r"$L/R$", "g/R": r"$g/R$"}
_LABEL_TOKENS = re.compile("|".join(re.escape(t) for t in sorted(_LABEL_TEX, key=len, reverse=True)))


def budget_label_tex(label: str) -> str:
    """A headline's plain label ('first threshold [pi^2 EI/L^2], L/R = 10') as LaTeX: its units and
    symbols set in math, the rest escaped."""
    out, end = [], 0
    for m in _LABEL_TOKENS.finditer(label):
        out += [tex_escape(label[end:m.start()]), _LABEL_TEX[m.group()]]
        end = m.end()
    return "".join(out) + tex_escape(label[end:])


def ensemble_ladder_macros(name: str, ds: xr.Dataset, macros: Macros) -> None:
    """A ladder of seed ensembles: \\val{<ladder>.seeds} (runs per rung at the equilibrium it
    decides on), and per compared quantity q (F_transmitted, L_z, decay_ratio, ...) the shift of the
    publication rung's mean from the finest rung, \\val{<ladder>.shift.<q>} ('+1.2 +- 0.8 %'), with
    the shift the ensembles resolve at 95 % power, \\val{<ladder>.resolution.<q>} ('2.1 %'); 'not
    measured' where a quantity was not compared; \\val{<ladder>.loosely_wound}, the loosely wound
    seeds of every rung out of those with a regular helix ('none' if no seed is)."""
    from ..analysis.figures.convergence import RELATION_KEYS, STATE_KEYS, loose_counts

    macros.add("val", f"{name}.seeds", str(int(ds["n_seeds"].values.min())))
    # the loosely wound seeds per rung, '2 of 20 at 512, 9 of 32 at 1024' (analysis.local_relations)
    loose, counts = "none", loose_counts(ds)
    if counts is not None and counts[0].sum():
        loose = ", ".join(f"{int(n)} of {int(t)} at {float(v):g}" for n, t, v in zip(*counts, ds["value"].values))
    macros.add("val", f"{name}.loosely_wound", loose)
    finest = ds.sizes["rung"] - 1
    pub = int(np.flatnonzero(np.isclose(ds["value"].values, float(ds.attrs["publication_value"]), rtol=1e-9))[0])
    for r, region in enumerate(REGIONS):
        # the shift of F(L) between the publication and the finest rung, split by region (analysis.regions);
        # an l0 ladder's also as \val{l0_ladder.region.<region>} for the text
        if "F_shift_by_region" in ds and int(ds["F_shift_by_region_has"].values[pub]):
            text = pm(100 * float(ds['F_shift_by_region'].values[pub, r]),
                      100 * float(ds['F_shift_by_region_se'].values[pub, r]), sign=True) + " %"
            macros.add_text("val", f"{name}.region.{region}", text)
            if str(ds.attrs["parameter"]) == "l0":
                macros.add_text("val", f"l0_ladder.region.{region}", text)
        else:
            macros.add("val", f"{name}.region.{region}", "not measured")
    if str(ds.attrs["parameter"]) == "l0":
        # the text's view of the frictional l0 ladder: the publication rung's shifts against every finer one
        for quantity, key in (("F_transmitted", "F_shifts"), ("decay_ratio", "decay_shifts")):
            qs = list(ds["quantity"].values)
            if quantity not in qs:
                continue
            q = qs.index(quantity)
            parts = [pm(100 * float(ds['cmp_shift'].values[j, q]), 100 * float(ds['cmp_shift_se'].values[j, q]),
                        sign=True) + f" % against {float(ds['value'].values[j]):g}"
                     for j in range(pub + 1, ds.sizes["rung"]) if int(ds["cmp_verdict_code"].values[j, q])]
            if parts:
                macros.add_text("val", f"l0_ladder.{key}", " and ".join(parts))
        from ..analysis.figures.convergence import verdict_word
        macros.add("val", "l0_ladder.verdict", verdict_word(str(ds.attrs["status"])))
        if "F_transmitted" in list(ds["quantity"].values):
            # the 95 % bound of the publication rung's F(L) shift against the finest rung, beside its tolerance
            q = list(ds["quantity"].values).index("F_transmitted")
            j = ds.sizes["rung"] - 1
            if int(ds["cmp_verdict_code"].values[j, q]):
                t95 = distributions.t_quantiles(float(ds["cmp_dof"].values[j, q])
                                                if ds["cmp_dof"].values[j, q] > 0 else math.inf)[0]
                bound = 100 * (abs(float(ds["cmp_shift"].values[j, q])) + t95 * float(ds["cmp_shift_se"].values[j, q]))
                macros.add("val", "l0_ladder.F_bound", f"{bound:.2g} % (tolerance "
                           f"{100 * float(ds['cmp_compared_tolerance'].values[j, q]):.2g} %)")
        if "lower_friction_use" in ds:
            # the lower region's friction use per rung, coarse to fine (where the ladder's F(L) moves)
            use = ", ".join(pm(float(m), float(e)) for m, e in
                            zip(ds["lower_friction_use"].values, ds["lower_friction_use_sem"].values))
            values = ", ".join(f"{float(v):g}" for v in ds["value"].values)
            macros.add_text("val", "l0_ladder.lower_friction_use", f"{use} at link lengths {values}")
    if "F_shift_split_total" in ds and int(ds["F_shift_by_region_has"].values[pub]):
        total = pm(100 * float(ds['F_shift_split_total'].values[pub]),
                   100 * float(ds['F_shift_split_total_se'].values[pub]), sign=True) + " %"
        seeds = str(int(ds["F_shift_split_seeds"].values[pub]))
        macros.add_text("val", f"{name}.region.total", total)
        macros.add("val", f"{name}.region.seeds", seeds)
        if str(ds.attrs["parameter"]) == "l0":
            macros.add_text("val", "l0_ladder.region.total", total)
            macros.add("val", "l0_ladder.region.seeds", seeds)
    quantities = list(ds["quantity"].values)
    for quantity in (*RELATION_KEYS, *STATE_KEYS):
        q = quantities.index(quantity) if quantity in quantities else None
        if q is None or int(ds["cmp_verdict_code"].values[finest, q]) == 0:
            # not compared: no regular helix (or fewer than two values) on a rung
            macros.add("val", f"{name}.shift.{quantity}", "not measured")
            macros.add("val", f"{name}.resolution.{quantity}", "not measured")
            continue
        shift, se = 100 * float(ds["cmp_shift"].values[finest, q]), 100 * float(ds["cmp_shift_se"].values[finest, q])
        macros.add_text("val", f"{name}.shift.{quantity}", pm(shift, se, sign=True) + " %")
        macros.add_text("val", f"{name}.resolution.{quantity}",
                        format(100 * float(ds["cmp_resolution"].values[finest, q]), ".2g") + " %")


def short_status(status: str, limit: int = STATUS_CHARS) -> str:
    """A convergence verdict for the table: as it is up to `limit` characters, else its
    headlines (figures.convergence.brief_status), else cut at the last word boundary before
    the limit (the table's caption points to the full text in results/checks/<figure>.txt)."""
    from ..analysis.figures.convergence import brief_status

    for text in (status, brief_status(status)):
        if len(text) <= limit:
            return text
    return status[:status.rfind(" ", 0, limit)].rstrip(",;:") + " ..."


def ours_text(v: Verdict) -> str:
    """Our value as the tables and \\ours print it: with its error where the measure gives one,
    rounded together (pm)."""
    if v.ours_error is not None and v.ours_value is not None and v.ours_error > 0:
        return pm(v.ours_value, v.ours_error)
    return v.ours


def _value_cell(text: str, quantity: str) -> tuple[str, str]:
    """A number of the tables as LaTeX and as plain text, after its quantity where the claim
    names one ('F(L)/F(0) = 0.0528'); a text as it is."""
    tex, plain = tex_value(text)
    if " +- " in text:
        tex, plain = pm_tex(text)
    elif not is_number(text):
        return tex, plain
    if quantity:
        return rf"{tex_escape(quantity)} = {tex}", f"{quantity} = {plain}"
    return tex, plain


def _verdict_cell(v: Verdict, why: bool = True) -> str:
    """The verdict in bold, with the part that holds (partly reproduced) and, with ``why``, what
    leaves an inconclusive claim undecided (the one-page results table leaves that to the claims
    table)."""
    # words not hyphenated (the PDF check reads the verdict back word for word)
    part = v.part if (why or v.verdict == "partly reproduced") else ""
    return r"\textbf{" + " ".join(rf"\mbox{{{tex_escape(w)}}}" for w in v.verdict.split()) + "}" \
        + (f" ({tex_escape(part)})" if part else "")


def claims_table(verdicts: Iterable[Verdict]) -> str:
    """A long table, one row per claim: label C<n>, where in the original, claim, paper, ours,
    verdict."""
    rows = []
    for i, v in enumerate(verdicts, 1):
        ours = _value_cell(ours_text(v), v.quantity)[0]
        paper = _value_cell(v.paper, v.quantity)[0]
        rows.append(rf"C{i} & {tex_escape(v.where)} & {caption_tex(v.claim)} & {paper} & {ours} & "
                    rf"{_verdict_cell(v)} \\")
    col = r">{\raggedright\arraybackslash}p"
    head = (rf"\begin{{longtable}}{{@{{}}{col}{{0.035\linewidth}}{col}{{0.12\linewidth}}{col}{{0.39\linewidth}}"
            rf"{col}{{0.13\linewidth}}{col}{{0.13\linewidth}}{col}{{0.1\linewidth}}@{{}}}}" "\n"
            r"\caption{Every checkable statement of the original paper, with the paper's value, ours and the "
            rf"computed verdict (rule \texttt{{claims}}: \texttt{{{layout.CLAIMS_CSV}}}, with the evidence and the "
            r"tolerance of each). ``Where'' is the section, equation or figure of the original; a number is given "
            r"with the quantity it measures and, for a mean over seeds, with its standard error. The readings "
            r"behind ``reproduced under reading'' are in Table~\ref{tab:readings}.}"
            r"\label{tab:claims}\\" "\n"
            r"\hline & where (original) & claim & paper & ours & verdict \\ \hline\endfirsthead" "\n"
            r"\hline & where (original) & claim & paper & ours & verdict \\ \hline\endhead" "\n"
            r"\hline\endfoot")
    return "% GENERATED by confined_rod.claims.manuscript. Do not edit.\n" + head + "\n" + "\n".join(rows) + \
        "\n\\end{longtable}\n"


#: a cell of the one-page results table longer than this refers to the claims table instead
RESULT_CELL_CHARS = 30


#: the loading protocols (the scene parameter ``protocol``; tests check that every choice has a
#: name) as the results table names them
PROTOCOL_NAMES = {"straight": "full load at once", "planar": "planar", "planar_then_3d": "planar, then 3-D",
                  "ramp": "load ramp", "helix": "helical start"}


def _protocol_cell(v: Verdict) -> str:
    if not v.protocol:
        return "derivation" if "derivations" in v.evidence else "--"
    names = [PROTOCOL_NAMES.get(p, p) for p in v.protocol.split(", ")]
    return tex_escape("; ".join(names) if len(names) <= 2 else f"{len(names)} protocols")


def results_table(verdicts: Iterable[Verdict]) -> str:
    """The one-page results table of the main text: every claim by its label, the paper's value
    and ours (with the quantity and the standard error where there is one), the loading protocol
    of the runs that decided it, and the verdict; a text too long for the page (a formula) is in
    the claims table (same row label C<n>), a number never."""
    rows = []
    for i, v in enumerate(verdicts, 1):
        cells = []
        for text in (v.paper, ours_text(v)):
            tex, plain = _value_cell(text, v.quantity)
            # a number is always shown; a long text (a formula) is in the claims table
            number = is_number(text.split(" ")[0])
            cells.append(tex if number or len(plain) <= RESULT_CELL_CHARS else r"Table~\ref{tab:claims}")
        rows.append(rf"C{i} & {tex_escape(v.label)} & {cells[0]} & {cells[1]} & {_protocol_cell(v)} & "
                    rf"{_verdict_cell(v, why=False)} \\")
    col = r">{\raggedright\arraybackslash}p"
    return ("% GENERATED by confined_rod.claims.manuscript. Do not edit.\n"
            r"\begin{table*}[p]" "\n"
            r"\caption{The results: every claim of the original (and, marked in the claims table, of ours), the "
            r"paper's value and ours ($\pm$ its error where the measure gives one: the standard error of a mean over "
            r"seeds, for a single rod or a threshold the error its note states), the loading protocols of the "
            r"datasets and runs the claim read, and the computed verdict. The statements, where they stand in the "
            r"original, the tolerances and the notes are in Table~\ref{tab:claims} under the same label.}"
            r"\label{tab:results}" "\n"
            r"\scriptsize" "\n"
            rf"\begin{{tabular}}{{@{{}}{col}{{0.035\textwidth}}{col}{{0.27\textwidth}}{col}{{0.2\textwidth}}"
            rf"{col}{{0.22\textwidth}}{col}{{0.11\textwidth}}{col}{{0.12\textwidth}}@{{}}}}" "\n"
            r"\hline & claim & paper & ours & protocol & verdict \\ \hline" "\n"
            + "\n".join(rows) + "\n" r"\hline" "\n" r"\end{tabular}" "\n" r"\end{table*}" "\n")


def readings_table(verdicts: Iterable[Verdict]) -> str:
    rows = [rf"C{i} & {tex_escape(v.reading)} \\" for i, v in enumerate(verdicts, 1) if v.reading]
    return ("% GENERATED by confined_rod.claims.manuscript. Do not edit.\n"
            r"\begin{longtable}{@{}p{0.06\linewidth}p{0.9\linewidth}@{}}" "\n"
            r"\caption{The readings under which claims are tested, where the original leaves something open; a "
            r"claim that holds under its reading is ``reproduced under reading''.}\label{tab:readings}\\" "\n"
            r"\hline claim & reading \\ \hline\endfirsthead" "\n" r"\hline\endfoot" "\n"
            + "\n".join(rows) + "\n\\end{longtable}\n")


def provenance(figure: str, ds: xr.Dataset, config_name: str) -> str:
    """One sentence of LaTeX: config, git commit, the dataset file (file names, commit and package
    in typewriter type)."""
    commit = str(ds.attrs.get("git_commit", "unknown"))[:12]

    def tt(text: str) -> str:
        return r"\texttt{" + tex_escape(text) + "}"
    return (f"Provenance: config {tt(config_name)}, git commit {tt(commit)}, dataset "
            f"{tt(layout.dataset_path(figure))} ({tt('confined_rod')} "
            f"{tex_escape(str(ds.attrs.get('confined_rod_version', '?')))}).")


#: REVTeX 4.2 (pre, twocolumn): \textwidth and \textheight in TeX points (tests/test_caption_tex.py
#: checks them against pdflatex). A figure is included at its natural size, scaled down only if it
#: is wider than \textwidth or taller than FIGURE_MAX_HEIGHT \textheight (figure_scale()).
TEXTWIDTH_PT = 510.0
TEXTHEIGHT_PT = 672.0
FIGURE_MAX_HEIGHT = 0.62
_BP_PER_PT = 72.0 / 72.27          # PDF (and matplotlib) points are big points, 1/72 in


def figure_scale(width_bp: float, height_bp: float) -> float:
    """The factor by which figures.tex prints a figure whose PDF is width_bp x height_bp big points."""
    return min(1.0, TEXTWIDTH_PT * _BP_PER_PT / width_bp,
               FIGURE_MAX_HEIGHT * TEXTHEIGHT_PT * _BP_PER_PT / height_bp)


#: \crfigure{file}: the figure at its natural size, capped at \textwidth and at
#: FIGURE_MAX_HEIGHT \textheight (keeping its aspect ratio); lengths of its own, since graphicx
#: uses the scratch registers
FIGURE_MACRO = "%\n".join([
    r"\ifdefined\crfigwidth\else\newlength{\crfigwidth}\newlength{\crfigheight}\fi",
    r"\providecommand{\crfigure}[1]{\begingroup\sbox0{\includegraphics{#1}}",
    r"\setlength{\crfigwidth}{\wd0}\ifdim\crfigwidth>\textwidth\setlength{\crfigwidth}{\textwidth}\fi",
    rf"\setlength{{\crfigheight}}{{\ht0}}\ifdim\crfigheight>{FIGURE_MAX_HEIGHT}\textheight",
    rf"\setlength{{\crfigheight}}{{{FIGURE_MAX_HEIGHT}\textheight}}\fi",
    r"\includegraphics[width=\crfigwidth,height=\crfigheight,keepaspectratio]{#1}\endgroup}"]) + "%"


def served_checks(figure: str, datasets: Mapping[str, xr.Dataset]) -> list[tuple[str, str, str, str]]:
    """The convergence ladders that vouch for a figure (their ``serves``): (ladder, the figure's
    scene, parameter, verdict word) each, so a caption says when the check of its numerics fails."""
    from ..analysis.figures.convergence import verdict_word

    out = []
    for ladder, ds in sorted(datasets.items()):
        if ds.attrs.get("kind") != "convergence":
            continue
        for fig, scene in re.findall(r"([^\s,.()]+)\.([^\s,.()]+) \(", str(ds.attrs.get("serves", "none"))):
            if fig == figure:
                out.append((ladder, scene, str(ds.attrs["parameter"]), verdict_word(str(ds.attrs.get("status", "")))))
    return out


def figures_tex(order: list[tuple[str, int | None]], captions: Mapping[str, str],
                datasets: Mapping[str, xr.Dataset], config_name: str, placement: str = "tp") -> str:
    """One float per figure (paper figures first, in the paper's order), each with its caption
    and provenance, labelled fig:<name>; and \\figref{name}, which names a figure of the
    config or says that this config does not build it. ``placement``: where LaTeX may put the
    floats (tp: at the top of a text page or on a float page; p: float pages only)."""
    out = ["% GENERATED by confined_rod.claims.manuscript. Do not edit.", FIGURE_MACRO]
    for name, paper_figure in order:
        checks = served_checks(name, datasets)
        checked = ("" if not checks else " Its numerics are checked by " + ", ".join(
            rf"\texttt{{{tex_escape(ladder)}}} (scene {tex_escape(scene)}, {tex_escape(param)}): "
            rf"\textbf{{{tex_escape(word)}}}" for ladder, scene, param, word in checks)
            + r" (Table~\ref{tab:convergence}).")
        cap = caption_tex(captions[name]) + checked + " " + provenance(name, datasets[name], config_name)
        out += [rf"\begin{{figure*}}[{placement}]", r"\centering", rf"\crfigure{{{name}.pdf}}",
                rf"\caption{{{cap}}}", rf"\label{{fig:{name}}}", r"\end{figure*}", ""]
    return "\n".join(out) + "\n"


def figure_macros(order: list[tuple[str, int | None]], macros: Macros) -> None:
    """\\figref{name}: 'Fig. n' of a figure this config builds, or a note that it does not."""
    macros.raw.append(r"\newcommand{\figref}[1]{\ifcsname cr@fig@#1\endcsname Fig.~\ref{fig:#1}\else"
                      r" (figure \texttt{\detokenize{#1}} is not built by this config)\fi}")
    macros.raw += [rf"\expandafter\def\csname cr@fig@{_key(name)}\endcsname{{}}" for name, _ in order]


def figure_order(config: Mapping[str, Any]) -> list[tuple[str, int | None]]:
    """The figures as the manuscript numbers them: the main part's (paper figures in the paper's
    order, then the others in config order), then the supplement's (``supplement: true``) in config
    order."""
    figs = [(name, cfg.get("paper_figure")) for name, cfg in config["figures"].items()]
    paper = sorted([f for f in figs if f[1]], key=lambda f: f[1])
    ordered = paper + [f for f in figs if not f[1]]
    extra = in_supplement(config)
    return [f for f in ordered if f[0] not in extra] + [f for f in figs if f[0] in extra]


def in_supplement(config: Mapping[str, Any]) -> set[str]:
    """The figures the manuscript prints in its supplement (their entry's ``supplement: true``)."""
    return {name for name, cfg in config["figures"].items() if cfg.get("supplement")}


def write_expected(macros: Macros, n_figures: int, verdicts: Iterable[Verdict]) -> str:
    return json.dumps({"macros": macros.expected(), "n_figures": n_figures,
                       "claims": [{"label": f"C{i}", "id": v.id, "verdict": v.verdict,
                                   "ours": _value_cell(ours_text(v), "")[1], "paper": _value_cell(v.paper, "")[1]}
                                  for i, v in enumerate(verdicts, 1)]}, indent=1)


def verdicts_from_dataset(ds: xr.Dataset) -> list[Verdict]:
    """The claims dataset (rule claims) back as verdicts."""
    out = []
    for i, cid in enumerate(ds.claim.values):
        def text(name):
            return str(ds[name].values[i])

        def number(name):
            return float(ds[name].values[i]) if int(ds["has_" + name].values[i]) else None

        out.append(Verdict(str(cid), text("where"), text("statement"), text("paper"), number("paper_value"),
                           text("ours"), number("ours_value"), text("tolerance"), text("verdict"),
                           text("evidence"), text("reading"), text("note"),
                           text("finding") if "finding" in ds else str(cid), text("part"),
                           text("label"), text("quantity"), text("protocol"), number("ours_error")))
    return out


TEX_HINT = ("the paper needs TeX: latexmk, pdflatex and REVTeX 4.2. On Debian/Ubuntu: "
            "apt-get install latexmk texlive-publishers texlive-latex-recommended "
            "(tools/setup.sh does this when run as root); every other target builds without it")


def build_pdf(tex: str, sources: Iterable[str], figures: Iterable[str], output: str, timeout: float = 600) -> None:
    """latexmk in a private build folder (the manuscript, its generated parts and the figure
    PDFs copied in); fail on any LaTeX error or unresolved reference; move the PDF into place
    only when it is complete."""
    import os
    import shutil
    import subprocess
    import tempfile
    from pathlib import Path

    for exe in ("latexmk", "pdflatex"):
        if shutil.which(exe) is None:
            raise RuntimeError(f"{exe} not found: {TEX_HINT}")
    out = Path(output)
    out.parent.mkdir(parents=True, exist_ok=True)
    name = Path(tex).stem
    # the build folder lives outside results/, so a killed job leaves nothing half-written there
    with tempfile.TemporaryDirectory(prefix=f"confined_rod_paper_{name}_") as build:
        shutil.copy(tex, Path(build) / f"{name}.tex")
        for f in list(sources) + [f for f in figures if f.endswith(".pdf")]:
            shutil.copy(f, Path(build) / Path(f).name)
        cmd = ["latexmk", "-pdf", "-interaction=nonstopmode", "-halt-on-error", "-file-line-error", f"{name}.tex"]
        proc = subprocess.run(cmd, cwd=build, capture_output=True, text=True, timeout=timeout)
        log = (Path(build) / f"{name}.log")
        log_text = log.read_text(errors="replace") if log.exists() else ""
        if proc.returncode != 0:
            errors = [ln for ln in log_text.splitlines() if ln.startswith("!") or ".tex:" in ln]
            raise RuntimeError(f"latexmk failed on {tex} (exit {proc.returncode}):\n" + "\n".join(errors[-20:])
                               + "\n" + proc.stdout[-2000:])
        unresolved = [ln for ln in log_text.splitlines()
                      if re.search(r"(Reference|Citation) .* undefined|There were undefined references", ln)]
        if unresolved:
            raise RuntimeError(f"{tex}: unresolved references after latexmk:\n" + "\n".join(unresolved[:20]))
        print(proc.stdout[-1500:])
        os.replace(Path(build) / f"{name}.pdf", out)
