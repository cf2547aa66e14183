"""``report.html``: a result folder's report, one self-contained HTML file a browser shows
offline (figures as inline SVG, the style in the page; no script, no other file, nothing
fetched).

The page is a title and a list of :class:`Section` (an id, a heading, a body of HTML built with
:mod:`dynid.export.report_html`, every text escaped). :func:`write_report` builds the sections of
an identification (``dynid identify``) or a validation (``dynid validate``,
:mod:`dynid.export.report_sections`); a command with other content (e.g. an exciting
trajectory's q, qd, qdd and torque against their limits) builds its own sections and writes
them with :func:`write_page`, into the staging folder of :mod:`dynid.export.output_folder` so
that the page appears with the folder's other files or not at all.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any, Union

from .._version import dynid_version
from ..identification.log_identification import LogIdentification, LogValidation
from ..logs.log_files import Log
from .report_html import Section, text

PathLike = Union[str, Path]

REPORT_FILE = "report.html"

_STYLE = """
body { font-family: system-ui, sans-serif; margin: 1.5em auto; max-width: 68em; color: #222;
       padding: 0 1em; }
h1 { font-size: 1.5em; } h2 { font-size: 1.2em; border-bottom: 1px solid #ccc; }
nav a { margin-right: 1em; }
table { border-collapse: collapse; margin: 0.5em 0 1em; font-size: 0.9em; }
th, td { border: 1px solid #ddd; padding: 0.2em 0.6em; text-align: left; }
td.num { text-align: right; font-variant-numeric: tabular-nums; }
caption { text-align: left; font-weight: bold; padding: 0.3em 0; }
dl { display: grid; grid-template-columns: max-content auto; gap: 0.2em 1em; }
dt { font-weight: bold; } dd { margin: 0; }
figure { margin: 0.5em 0 1em; } figure svg { max-width: 100%; height: auto; }
figcaption { font-size: 0.85em; color: #555; }
.histograms { display: flex; flex-wrap: wrap; gap: 0.5em; }
.histograms figure { margin: 0; }
"""


def page(title: str, sections: Sequence[Section]) -> str:
    """The whole HTML document: title, links to the sections, the sections."""
    links = " ".join(f'<a href="#{text(s.key)}">{text(s.title)}</a>' for s in sections)
    parts = [
        "<!DOCTYPE html>",
        '<html lang="en">',
        '<head><meta charset="utf-8">',
        '<meta name="viewport" content="width=device-width, initial-scale=1">',
        f"<title>{text(title)}</title>",
        f"<style>{_STYLE}</style></head>",
        "<body>",
        f"<h1>{text(title)}</h1>",
        f"<p>written by dynid {text(dynid_version())}</p>",
        f"<nav>{links}</nav>",
    ]
    for section in sections:
        parts.append(
            f'<section id="{text(section.key)}"><h2>{text(section.title)}</h2>\n'
            f"{section.body}\n</section>"
        )
    parts.append("</body></html>\n")
    return "\n".join(parts)


def write_page(folder: PathLike, title: str, sections: Sequence[Section]) -> Path:
    """Write ``folder/report.html`` (``folder`` is a staging folder: the page is written whole
    with the folder, :mod:`dynid.export.output_folder`); returns its path."""
    path = Path(folder) / REPORT_FILE
    path.write_text(page(title, sections), encoding="utf-8")
    return path


def write_report(
    result_or_validation: LogIdentification | LogValidation,
    folder: PathLike,
    *,
    result: LogIdentification | None = None,
    log: Log | None = None,
    warnings: Sequence[str] = (),
    sources: dict[str, Any] | None = None,
) -> Path:
    """Write ``folder/report.html`` of an identification (``LogIdentification``: its training
    logs and fit, or ``log``, prepared, with the result's prediction) or of a validation
    (``LogValidation``, with the ``result`` it applied when given: its coefficients and training
    fit). ``warnings`` are the run's warnings (listed with the notes); ``sources`` names the
    inputs for the summary (validate: ``result``, ``log``). Returns the path."""
    from .report_sections import identification_sections, validation_sections

    if isinstance(result_or_validation, LogIdentification):
        subject = result_or_validation
        sections = identification_sections(subject, log=log, warnings=warnings)
        title = f"dynid identify: {subject.model.get('name') or 'robot'}"
    elif isinstance(result_or_validation, LogValidation):
        if result is not None and not isinstance(result, LogIdentification):
            raise ValueError(
                f"result: expected a LogIdentification or None, got {type(result).__name__}"
            )
        sections = validation_sections(
            result_or_validation, result=result, warnings=warnings, sources=sources or {}
        )
        name = result.model.get("name") if result is not None else None
        title = f"dynid validate: {name or 'robot'}"
    else:
        raise ValueError(
            "result_or_validation: expected a LogIdentification or a LogValidation, got "
            f"{type(result_or_validation).__name__}"
        )
    return write_page(folder, title, sections)
