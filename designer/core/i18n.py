"""The build sheets' languages: English (the source text) and Spanish (the seed
documents' students read Spanish), with the words from a gettext message
catalogue and the numbers written as each language writes them.

The catalogue is ``designer/locale/<lang>/LC_MESSAGES/designer.po``, read by
Babel's ``read_po`` when a sheet is first written in that language (no compiled
``.mo`` file to keep in step: the ``.po`` file is the one source). English is
the text in the code itself, so an English sheet never reads a catalogue and
is the same as before the catalogue existed.

The language of a sheet is a context (:func:`language`): a command enters it
once around writing its files and its summary, and every renderer below asks
:func:`gettext` (imported as ``_``) for its words. Texts that are data before
they are words (a table's labels) are marked with :func:`N_` where they are
written and translated where they are shown. ``python -m designer.core.i18n``
lists the messages the code marks and the catalogue lacks (exit status 1 when
any); ``--update`` adds them to the ``.po`` file with an empty translation.

Numbers: CLDR (through Babel's ``get_decimal_symbol``) gives the decimal symbol,
a comma in Spanish (``1,6 kΩ``); Spanish sheets also write the ohm as ``Ω``
(the SI symbol, as the seed documents do), where the English sheets keep ``Ohm``
as they always have.

The web page's words are messages of the same catalogue: its scripts' ``D.t("...")`` calls (Babel's
JavaScript extractor) and its HTML's text, titles, placeholders and labels (:func:`page_messages`); the
server answers them as JSON (:func:`page_catalogue`, ``GET /api/catalogue?lang=es``), a language
negotiated from the browser's ``Accept-Language`` (:func:`negotiate`, Babel's ``negotiate_locale``).
"""

from __future__ import annotations

import contextvars
import functools
import re
import sys
from contextlib import contextmanager
from pathlib import Path

from .errors import DesignError

__all__ = ["DEFAULT", "LANGUAGES", "Message", "N_", "catalogue", "check_language", "current", "extract", "gettext", "language",
           "html_words", "localise", "missing", "negotiate", "page_catalogue", "page_messages", "translated",
           "update_catalogue"]

#: the languages a sheet can be written in (English first: the default and the source text)
LANGUAGES = ("en", "es")
#: the language when none is asked for (whatever the machine's LANG says: a sheet reads the same everywhere)
DEFAULT = "en"
#: the catalogues: <LOCALE_DIR>/<lang>/LC_MESSAGES/<DOMAIN>.po
LOCALE_DIR = Path(__file__).resolve().parent.parent / "locale"
DOMAIN = "designer"
#: the functions whose string arguments are messages (Babel's extractor looks for their calls)
KEYWORDS = {"_": None, "gettext": None, "N_": None}
#: the web page's files (its scripts and HTML; not the vendored plotting library)
STATIC_DIR = LOCALE_DIR.parent / "web" / "static"
#: the page's scripts mark their words as ``D.t("...")`` (translated there) or ``D.N_("...")`` (shown later),
#: the first argument a string literal or literals joined by ``+``. (Babel's JavaScript extractor loses a call
#: nested in another's arguments, ``D.t("{a}", {a: D.t("b")})``, which the page writes often: a regular
#: expression over the call's literal is exact for this one form.)
_JS_STRING = re.compile(r'"(?:[^"\\\n]|\\.)*"|\'(?:[^\'\\\n]|\\.)*\'')
_PAGE_CALL = re.compile(r"\bD\.(?:t|N_)\(\s*((?:%s)(?:\s*\+\s*(?:%s))*)" % (_JS_STRING.pattern, _JS_STRING.pattern))
#: the attributes of the page's HTML that a reader sees or hears
PAGE_ATTRIBUTES = ("placeholder", "title", "aria-label", "alt")
#: HTML's elements without an end tag
VOID = ("area", "base", "br", "col", "embed", "hr", "img", "input", "link", "meta", "source", "track", "wbr")

_CURRENT = contextvars.ContextVar("designer_language", default=DEFAULT)


def check_language(lang) -> str:
    """The language code, checked.

    Parameters
    ----------
    lang : str or None
        ``en`` or ``es``; None is :data:`DEFAULT`.

    Returns
    -------
    str
        The code.
    """
    if lang is None:
        return DEFAULT
    if lang not in LANGUAGES:
        raise DesignError(f"lang must be one of {', '.join(LANGUAGES)}, got {str(lang)!r}", "lang")
    return lang


@contextmanager
def language(lang):
    """``with language("es"):`` the sheets rendered in the block are in that language.

    Parameters
    ----------
    lang : str or None
        A code of :data:`LANGUAGES`; None keeps the current language.

    Yields
    ------
    str
        The language in force.
    """
    if lang is None:
        yield current()
        return
    token = _CURRENT.set(check_language(lang))
    try:
        yield lang
    finally:
        _CURRENT.reset(token)


def current() -> str:
    """The language sheets are rendered in now.

    Returns
    -------
    str
        Its code.
    """
    return _CURRENT.get()


def catalogue_path(lang: str) -> Path:
    """Where the catalogue of ``lang`` is."""
    return LOCALE_DIR / lang / "LC_MESSAGES" / f"{DOMAIN}.po"


@functools.lru_cache(maxsize=None)
def catalogue(lang: str) -> dict:
    """The translated messages of ``lang``: msgid -> msgstr (untranslated and fuzzy entries left out).

    Parameters
    ----------
    lang : str
        A code of :data:`LANGUAGES` other than English.

    Returns
    -------
    dict
        The messages.
    """
    return {m.id: m.string for m in _read_po(lang) if m.id and isinstance(m.id, str) and m.string and not m.fuzzy}


def _read_po(lang: str):
    """The ``.po`` file of ``lang`` as Babel's Catalog."""
    from babel.messages.pofile import read_po
    with open(catalogue_path(lang), "rb") as f:
        return read_po(f, locale=lang, domain=DOMAIN)


def gettext(message: str) -> str:
    """``message`` in the current language (as written when the catalogue has no translation).

    Parameters
    ----------
    message : str
        The English text.

    Returns
    -------
    str
        The text to show.
    """
    lang = _CURRENT.get()
    if lang == "en" or not message:
        return message
    return catalogue(lang).get(message, message)


def N_(message: str) -> str:  # noqa: N802  (gettext's conventional name)
    """Mark ``message`` for the catalogue without translating it (translated where it is shown).

    Parameters
    ----------
    message : str
        The English text.

    Returns
    -------
    str
        The same text.
    """
    return message


class Message(str):
    """A note written in English that keeps its message and values, so that a sheet shows it in its own
    language (:func:`translated`): the text itself (``result.json``'s, a ``str`` everywhere) is the English.

    Parameters
    ----------
    message : str
        The English text with ``{name}`` fields, marked ``N_`` where it is written (for the catalogue).
    **values
        The fields' values: text (numbers already written, ``f"{x:.3g}"``), or a :class:`Message` of their own.
    """

    def __new__(cls, message: str, /, **values):
        self = super().__new__(cls, message.format(**values))
        self.message, self.values = message, values
        return self

    @classmethod
    def joined(cls, sep: str, items) -> "Message":
        """``items`` (messages or text) joined by ``sep``, each shown in the sheet's language.

        Parameters
        ----------
        sep : str
            What goes between two items.
        items : iterable of str
            The items.

        Returns
        -------
        Message
            The list.
        """
        items = list(items)
        return cls(sep.replace("{", "{{").replace("}", "}}").join(f"{{i{k}}}" for k in range(len(items))),
                   **{f"i{k}": v for k, v in enumerate(items)})

    def __reduce__(self):
        # copies and pickles (dataclasses.asdict, worker processes) keep the message and its values
        return (_message, (self.message, self.values))


def _message(message, values):
    return Message(message, **values)


def translated(text):
    """``text`` in the current language: a :class:`Message` filled with its values, each shown the same way (a
    value that is a word of the catalogue translated too); another string as :func:`gettext` has it.

    Parameters
    ----------
    text : str
        A :class:`Message` or plain text.

    Returns
    -------
    str
        The text to show.
    """
    if isinstance(text, Message):
        return gettext(text.message).format(**{k: translated(v) for k, v in text.values.items()})
    return gettext(text) if isinstance(text, str) else text


# a decimal point: between digits, and not part of a dotted run (1.2.3) or a name (v1.5, file2.3.csv); a
# gain's "x" (x2.57) and a sentence's full stop after the number (= 30.3.) are no names
_DECIMAL = re.compile(r"(?<![A-Za-wyz_.\d])(\d+)\.(\d+)(?!\.?\d)")
# the ohm after a number and its SI prefix (1.6 kOhm, 50 Ohm, 100 kOhm)
_OHM = re.compile(r"(?<=\d )([fpnumkMG]?)Ohm\b")
# micro written u in the English sheets' ASCII (43.2 us, 10 uF): the SI sign
_MICRO = re.compile(r"(?<=\d )u(?=(?:s|F|V|A|H|Hz)\b)")


@functools.lru_cache(maxsize=None)
def _decimal_symbol(lang: str) -> str:
    from babel.numbers import get_decimal_symbol
    return get_decimal_symbol(lang)


def localise(text: str) -> str:
    """Numbers and units in ``text`` as the current language writes them: the decimal
    symbol (a comma in Spanish) and, outside English, ``Ω`` for ``Ohm`` and ``µ`` for a ``u`` prefix.

    Parameters
    ----------
    text : str
        A sheet's text, written with decimal points.

    Returns
    -------
    str
        The text in the current language's notation (unchanged in English).
    """
    lang = _CURRENT.get()
    if lang == "en" or not isinstance(text, str):
        return text
    dec = _decimal_symbol(lang)
    text = _DECIMAL.sub(lambda m: f"{m.group(1)}{dec}{m.group(2)}", text)
    return _MICRO.sub("µ", _OHM.sub(r"\1Ω", text))


def extract(root: Path | None = None) -> dict:
    """Every message the package marks (Babel's extractor over its Python files; the web page's too).

    Parameters
    ----------
    root : Path or None
        The package's folder (default: this package's).

    Returns
    -------
    dict
        msgid -> the places it is marked ("path:line").
    """
    from babel.messages.extract import extract_from_dir
    root = root or LOCALE_DIR.parent
    out: dict = {}
    for path, line, msg, _comments, _context in extract_from_dir(str(root), [("**.py", "python")], keywords=KEYWORDS):
        if isinstance(msg, str) and msg:
            out.setdefault(msg, []).append(f"{path}:{line}")
    if root == LOCALE_DIR.parent:   # the package's: its web page's words too
        for msg, where in page_messages().items():
            out.setdefault(msg, []).extend(where)
    return out


def page_messages(root: Path | None = None) -> dict:
    """Every message of the web page: its scripts' ``D.t("...")`` and ``D.N_("...")`` calls and its HTML's words.

    Parameters
    ----------
    root : Path or None
        The page's folder (default: this package's ``web/static``).

    Returns
    -------
    dict
        msgid -> the places it is marked ("path:line").
    """
    import ast
    root = root or STATIC_DIR
    out: dict = {}
    for path in sorted(root.glob("*.js")):
        text = path.read_text(encoding="utf-8")
        for m in _PAGE_CALL.finditer(text):
            msg = "".join(ast.literal_eval(lit) for lit in _JS_STRING.findall(m.group(1)))
            if msg:
                out.setdefault(msg, []).append(f"web/static/{path.name}:{text.count(chr(10), 0, m.start()) + 1}")
    for path in sorted(root.glob("*.html")):
        for line, msg in html_words(path.read_text(encoding="utf-8")):
            out.setdefault(msg, []).append(f"web/static/{path.name}:{line}")
    return out


def html_words(html: str) -> list:
    """The words of an HTML page as a reader meets them: each text between tags (spaces collapsed, as the
    page's ``D.translatePage`` keys them) and each attribute of :data:`PAGE_ATTRIBUTES`; scripts, styles and
    texts without a letter left out.

    Parameters
    ----------
    html : str
        The page.

    Returns
    -------
    list
        (line, text) pairs.
    """
    from html.parser import HTMLParser
    found = []

    def keep(text, line):
        text = " ".join(text.split())
        if re.search(r"[A-Za-z]", text):
            found.append((line, text))

    class Words(HTMLParser):
        skip = 0
        closes: list = []   # the tags whose end ends a skip (a script, a style, an element marked translate="no")

        def handle_starttag(self, tag, attrs):
            quiet = tag in ("script", "style") or ("translate", "no") in attrs
            if quiet and tag not in VOID:
                self.skip += 1
                self.closes = self.closes + [tag]
            for k, v in attrs:
                if k in PAGE_ATTRIBUTES and v and not quiet and not self.skip:
                    keep(v, self.getpos()[0])

        def handle_endtag(self, tag):
            if self.closes and self.closes[-1] == tag:
                self.skip -= 1
                self.closes = self.closes[:-1]

        def handle_data(self, data):
            if not self.skip:
                keep(data, self.getpos()[0])

    Words(convert_charrefs=True).feed(html)
    return found


def page_catalogue(lang) -> dict:
    """What the web page needs to speak ``lang``: the catalogue's translations (the page's own words and the
    library's it shows, check titles among them) and how the language writes a number.

    Parameters
    ----------
    lang : str or None
        A code of :data:`LANGUAGES` (checked: :func:`check_language`).

    Returns
    -------
    dict
        ``lang``, ``decimal`` (the decimal symbol, CLDR's) and ``messages`` (English -> translation; empty
        for English).
    """
    lang = check_language(lang)
    return {"lang": lang, "decimal": _decimal_symbol(lang),
            "messages": {} if lang == "en" else dict(catalogue(lang))}


def negotiate(accept_language: str | None) -> str:
    """The language of :data:`LANGUAGES` a browser prefers (its ``Accept-Language`` header), else :data:`DEFAULT`.

    Parameters
    ----------
    accept_language : str or None
        The header (``es-ES,es;q=0.9,en;q=0.8``).

    Returns
    -------
    str
        A code of :data:`LANGUAGES`.
    """
    from babel import negotiate_locale
    wanted = []
    for item in str(accept_language or "").split(","):
        tag, _, q = item.strip().partition(";q=")
        try:
            weight = float(q) if q else 1.0
        except ValueError:
            continue
        if tag and weight > 0:
            wanted.append((weight, tag.strip().replace("_", "-")))
    ordered = [t for _w, t in sorted(wanted, key=lambda x: -x[0])]
    # a region's code ("es-AR") reads as its language's
    ordered = [p for t in ordered for p in (t, t.split("-")[0])]
    return negotiate_locale(ordered, list(LANGUAGES), sep="-") or DEFAULT


def missing(lang: str = "es") -> dict:
    """The marked messages the catalogue of ``lang`` does not translate.

    Parameters
    ----------
    lang : str
        The language.

    Returns
    -------
    dict
        msgid -> its places.
    """
    catalogue.cache_clear()
    have = catalogue(lang)
    return {m: where for m, where in extract().items() if m not in have}


def update_catalogue(lang: str = "es") -> int:
    """Add the marked messages the ``.po`` file lacks, with an empty translation (for a translator to fill).

    Parameters
    ----------
    lang : str
        The language.

    Returns
    -------
    int
        How many were added.
    """
    from babel.messages.pofile import write_po
    cat = _read_po(lang)
    added = 0
    for msg, where in extract().items():
        if msg not in cat:
            cat.add(msg, "", locations=[tuple(w.rsplit(":", 1)) for w in where])
            added += 1
    with open(catalogue_path(lang), "wb") as f:
        write_po(f, cat, width=116, omit_header=False, include_lineno=False, sort_output=True)
    catalogue.cache_clear()
    return added


def main(argv=None) -> int:
    """``python -m designer.core.i18n [--update]``: the messages the Spanish catalogue lacks.

    Parameters
    ----------
    argv : list of str or None
        The arguments.

    Returns
    -------
    int
        0 when the catalogue is complete, 1 when a message lacks its translation.
    """
    args = sys.argv[1:] if argv is None else argv
    if "--update" in args:
        print(f"added {update_catalogue()} messages to {catalogue_path('es')}")
    lack = missing("es")
    for msg, where in sorted(lack.items()):
        print(f"{where[0]}: no Spanish for {msg!r}")
    return 1 if lack else 0


if __name__ == "__main__":
    sys.exit(main())
