"""Translations: the catalogues in the package are current with the sources, complete, and chosen as the
environment says; the pseudo-locale made by the tooling translates every marked string.

``scripts/i18n.py`` is the tooling (``./rtmu-dev i18n``); these tests call it in-process.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from i18n_tooling import tooling
from rtmu.base import i18n

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture
def english_after() -> Iterator[None]:
    yield
    i18n.use(["en"])


def test_the_template_the_po_files_and_the_compiled_catalogues_are_current() -> None:
    assert tooling.stale(tooling.wanted()) == [], "run ./rtmu-dev i18n and commit what it wrote"


def test_every_shipped_language_is_compiled_into_the_package() -> None:
    assert tooling.languages(), "po/ holds no language"
    for language in tooling.languages():
        assert tooling.mo_path(language).is_file(), language


def test_the_pseudo_locale_accents_every_letter_keeps_placeholders_and_is_longer() -> None:
    for text in ("Stop", "Battery {percent} %", "%(count)d robots", "_Connect…", "a"):
        out = tooling.pseudo(text)
        assert len(out) >= 1.3 * len(text), (text, out)
        for kept in ("{percent}", "%(count)d", "_"):
            if kept in text:
                assert kept in out, (text, out)
        stripped = out.replace("{percent}", "").replace("%(count)d", "")
        assert not any("a" <= c.lower() <= "z" for c in stripped), out


def test_use_reads_the_pseudo_locale_and_its_plurals(tmp_path: Path, english_after: None) -> None:
    tooling.compile_pseudo(tmp_path)
    i18n.use([tooling.PSEUDO], tmp_path)
    template = tooling.extract()
    singular = next(m.id for m in template if isinstance(m.id, str) and m.id)
    assert i18n._(singular) == tooling.pseudo(singular)
    plural = next((m.id for m in template if isinstance(m.id, tuple)), None)
    if plural is not None:
        assert i18n.ngettext(plural[0], plural[1], 1) == tooling.pseudo(plural[0])
        assert i18n.ngettext(plural[0], plural[1], 5) == tooling.pseudo(plural[1])
    i18n.use(["en"])
    assert i18n._(singular) == singular


@pytest.mark.parametrize("variable", ["LANGUAGE", "LC_ALL", "LC_MESSAGES", "LANG"])
def test_the_language_comes_from_the_environment_as_gettext_reads_it(tmp_path: Path, variable: str) -> None:
    tooling.compile_pseudo(tmp_path)
    singular = next(m.id for m in tooling.extract() if isinstance(m.id, str) and m.id)
    env = {k: v for k, v in os.environ.items() if k not in ("LANGUAGE", "LC_ALL", "LC_MESSAGES", "LANG")}
    env[variable] = tooling.PSEUDO
    script = (
        "import sys; from pathlib import Path; from rtmu.base import i18n; "
        "i18n.use(localedir=Path(sys.argv[1])); print(i18n._(sys.argv[2]))"
    )
    out = subprocess.run(
        [sys.executable, "-c", script, str(tmp_path), singular],
        env=env,
        capture_output=True,
        text=True,
        check=True,
    ).stdout.strip()
    assert out == tooling.pseudo(singular)
    env[variable] = "C"
    out = subprocess.run(
        [sys.executable, "-c", script, str(tmp_path), singular],
        env=env,
        capture_output=True,
        text=True,
        check=True,
    ).stdout.strip()
    assert out == singular


def test_numbers_for_people_follow_the_locale_and_machine_output_does_not() -> None:
    assert i18n.number(1234.5, 1) in ("1234.5", "1,234.5")  # the suite runs in C.UTF-8
    assert f"{1234.5:.1f}" == "1234.5"


def test_german_is_complete() -> None:
    assert list(tooling.untranslated("de")) == []


PLACEHOLDER = re.compile(r"\{[^{}]*\}|%(?:\([^)]*\))?[sd%]")


@pytest.mark.parametrize("language", tooling.languages())
def test_every_translation_keeps_its_placeholders(language: str) -> None:
    """A translation that drops or renames ``{robot}`` (or argparse's ``%%``) would raise, or lie, where it is
    formatted."""
    wrong = []
    for message in tooling.read(tooling.PO_DIR / f"{language}.po", language):
        if not message.id:
            continue
        ids = message.id if isinstance(message.id, tuple) else (message.id,)
        strings = message.string if isinstance(message.string, tuple) else (message.string,)
        wanted = sorted(PLACEHOLDER.findall(ids[0]))
        wrong += [(ids[0], s) for s in strings if s and sorted(PLACEHOLDER.findall(s)) != wanted]
    assert wrong == []


def test_german_is_read_from_the_package_when_the_environment_asks_for_it() -> None:
    env = {k: v for k, v in os.environ.items() if k not in ("LANGUAGE", "LC_ALL", "LC_MESSAGES", "LANG")}
    env["LANG"] = "de_DE.UTF-8"
    script = (
        "from rtmu.base.i18n import _, ngettext; print(_('Battery')); "
        "print(ngettext('{count} value', '{count} values', 1)); "
        "print(ngettext('{count} value', '{count} values', 3))"
    )
    out = subprocess.run([sys.executable, "-c", script], env=env, capture_output=True, text=True, check=True)
    assert out.stdout.split("\n")[:3] == ["Akku", "{count} Wert", "{count} Werte"]


def test_a_connection_failure_is_said_in_german_and_the_host_as_it_is(english_after: None) -> None:
    """The window's "Could not connect" sentence: each marked part of the client's problem — advice."""
    from rtmu.client.diagnosis import ADVICE, login_finding
    from rtmu.protocol.commands import RejectReason
    from rtmu.ui.state_words import sentence_words

    i18n.use(["de"])
    finding = login_finding(RejectReason.BAD_USER_OR_PASSWORD)
    said = sentence_words(finding.sentence())
    assert said.startswith("falscher Benutzername oder falsches Passwort — ") and "--user" in said
    refused = sentence_words(f"connecting to robot.local:7272: connection refused — {ADVICE['refused']}")
    assert refused.startswith("connecting to robot.local:7272: connection refused — an diesem Port")
