"""RTMU's translations: extract ``po/rtmu.pot``, merge every ``po/<lang>.po``, compile the ``.mo``.

    ./rtmu-dev i18n                 # all three steps (run after changing marked strings or a .po)
    ./rtmu-dev i18n --check         # exit 1 when the .pot, a .po or a .mo is not current (CI, tests)
    ./rtmu-dev i18n --pseudo DIR    # the pseudo-locale (en_XA) compiled into DIR, for tests

Babel does the work: it is already pinned in the virtualenv (Sphinx brings it), it is pure Python (no
system package needed in CI or on a developer's machine), and its API lets the tests and this script
read, merge, compile and pseudo-translate catalogues in-process. Strings are marked with ``_``,
``ngettext`` and ``N_`` (``rtmu.base.i18n``); the compiled ``.mo`` are committed beside their ``.po``
under ``src/rtmu/data/locale`` so that the wheel and a checkout carry them without a build step, and
``tests/test_i18n.py`` fails when they are not current.
"""

from __future__ import annotations

import argparse
import io
import re
import sys
from collections.abc import Iterable
from datetime import UTC, datetime
from pathlib import Path

from babel.messages.catalog import Catalog, Message
from babel.messages.extract import extract_from_dir
from babel.messages.mofile import write_mo
from babel.messages.pofile import read_po, write_po

ROOT = Path(__file__).resolve().parents[1]
SOURCES = ROOT / "src" / "rtmu"
PO_DIR = ROOT / "po"
POT = PO_DIR / "rtmu.pot"
LOCALE_DIR = SOURCES / "data" / "locale"
DOMAIN = "rtmu"
PSEUDO = "en_XA"
"""The pseudo-locale's code (the region code Android and Windows use for it); never shipped."""
KEYWORDS = {"_": None, "N_": None, "ngettext": (1, 2)}


def extract() -> Catalog:
    """Every marked string under ``src/rtmu``, with where it is used."""
    catalog = Catalog(project="RTMU", domain=DOMAIN, charset="utf-8")
    for path, line, message, comments, context in extract_from_dir(
        str(SOURCES),
        method_map=[("**.py", "python")],
        keywords=KEYWORDS,
        comment_tags=["TRANSLATORS:"],
        strip_comment_tags=True,
    ):
        catalog.add(message, None, [(f"src/rtmu/{path}", line)], auto_comments=comments, context=context)
    return catalog


STAMP = datetime(2026, 1, 1, tzinfo=UTC)
"""The date written into every generated file, so that a file changes only when a message does."""


def po_bytes(catalog: Catalog) -> bytes:
    catalog.creation_date = catalog.revision_date = STAMP
    out = io.BytesIO()
    write_po(out, catalog, width=100, omit_header=False, sort_output=False, include_previous=False)
    return out.getvalue()


def mo_bytes(catalog: Catalog) -> bytes:
    catalog.creation_date = catalog.revision_date = STAMP
    out = io.BytesIO()
    write_mo(out, catalog, use_fuzzy=False)
    return out.getvalue()


def languages() -> list[str]:
    return sorted(p.stem for p in PO_DIR.glob("*.po"))


def read(path: Path, locale: str | None = None) -> Catalog:
    with path.open("rb") as handle:
        return read_po(handle, locale=locale, domain=DOMAIN)


def merged(language: str, template: Catalog) -> Catalog:
    """``po/<language>.po`` brought up to ``template``: new messages added, gone ones made obsolete."""
    catalog = read(PO_DIR / f"{language}.po", language)
    catalog.update(template, update_header_comment=False, no_fuzzy_matching=True)
    catalog.obsolete.clear()
    return catalog


def mo_path(language: str) -> Path:
    return LOCALE_DIR / language / "LC_MESSAGES" / f"{DOMAIN}.mo"


def wanted() -> dict[Path, bytes]:
    """Every generated file as it should be now."""
    template = extract()
    files = {POT: po_bytes(template)}
    for language in languages():
        catalog = merged(language, template)
        files[PO_DIR / f"{language}.po"] = po_bytes(catalog)
        files[mo_path(language)] = mo_bytes(catalog)
    return files


_ACCENTED = dict(
    zip(
        "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ",
        "áƀçđéƒĝĥíĵķļɱñöþʠŕšţûṽŵẋýžÅƁÇĐÉƑĜĤÎĴĶĻṀÑÖÞǪŔŠŢÛṼŴẊÝŽ",
        strict=True,
    )
)
_PLACEHOLDER = re.compile(r"\{[^{}]*\}|%(?:\([^)]*\))?[-#0 +]*\d*(?:\.\d+)?[sdifgxr%]|&[a-z]+;|_(?=\w)")


def pseudo(text: str) -> str:
    """``text`` with every letter accented and made at least 30 % longer, its placeholders (``{name}``,
    ``%d``, a mnemonic's ``_``) kept as they are: ``Stop`` → ``[Šţöþ~~]``."""
    if not text:
        return text
    out: list[str] = []
    last = 0
    for match in _PLACEHOLDER.finditer(text):
        out.append("".join(_ACCENTED.get(c, c) for c in text[last : match.start()]))
        out.append(match.group())
        last = match.end()
    out.append("".join(_ACCENTED.get(c, c) for c in text[last:]))
    body = "".join(out)
    padding = "~" * max(1, -(-len(text) * 4 // 10) - 2)
    return f"[{body}{padding}]"


def pseudo_catalog(template: Catalog) -> Catalog:
    catalog = Catalog(locale="en", domain=DOMAIN, charset="utf-8")
    for message in template:
        if not message.id:
            continue
        if isinstance(message.id, tuple):
            string: str | tuple[str, ...] = tuple(pseudo(form) for form in message.id)
        else:
            string = pseudo(message.id)
        catalog[message.id] = Message(message.id, string, context=message.context)
    return catalog


def compile_pseudo(directory: Path) -> Path:
    """The pseudo-locale, made from the sources' strings now, as ``DIR/en_XA/LC_MESSAGES/rtmu.mo``."""
    path = directory / PSEUDO / "LC_MESSAGES" / f"{DOMAIN}.mo"
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_bytes(mo_bytes(pseudo_catalog(extract())))
    return directory


def stale(files: dict[Path, bytes]) -> list[str]:
    return [str(p.relative_to(ROOT)) for p, data in files.items() if not p.exists() or p.read_bytes() != data]


def untranslated(language: str) -> Iterable[str]:
    for message in read(PO_DIR / f"{language}.po", language):
        strings = message.string if isinstance(message.string, tuple) else (message.string,)
        if message.id and (message.fuzzy or not all(strings)):
            yield message.id if isinstance(message.id, str) else message.id[0]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="./rtmu-dev i18n", description=__doc__.split("\n\n")[0])
    parser.add_argument("--check", action="store_true", help="only say whether every file is current")
    parser.add_argument("--add", metavar="LANG", help="start po/LANG.po (e.g. fr) from the template")
    parser.add_argument("--pseudo", type=Path, metavar="DIR", help="compile the pseudo-locale into DIR")
    args = parser.parse_args(argv)
    if args.pseudo:
        print(compile_pseudo(args.pseudo) / PSEUDO)
        return 0
    if args.add:
        new = PO_DIR / f"{args.add}.po"
        if new.exists():
            print(f"{new.relative_to(ROOT)} exists already", file=sys.stderr)
            return 1
        catalog = Catalog(locale=args.add, domain=DOMAIN, project="RTMU", charset="utf-8", fuzzy=False)
        catalog.update(extract())
        new.write_bytes(po_bytes(catalog))
    files = wanted()
    old = stale(files)
    if args.check:
        for name in old:
            print(f"not current: {name} (run ./rtmu-dev i18n)", file=sys.stderr)
        return 1 if old else 0
    for path in files:
        if str(path.relative_to(ROOT)) in old:
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_bytes(files[path])
            print(f"wrote {path.relative_to(ROOT)}")
    for language in languages():
        missing = list(untranslated(language))
        print(f"{language}: {len(missing)} of the messages untranslated or fuzzy")
    return 0


if __name__ == "__main__":
    sys.exit(main())
