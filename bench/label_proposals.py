"""Score the relation proposals on the labelled scikit-image photos; print or write the table.

python bench/label_proposals.py            # print the markdown table
python bench/label_proposals.py --write    # replace it in docs/labeling.md
"""

from __future__ import annotations

import argparse
from pathlib import Path

from seannet.provenance import ProcessState
from sgdata.errors import SgdataError
from sgdata.label.accuracy import score_proposals
from sgdata.label.classes import load_class_names
from sgdata.label.models import PhotoLabels
from sgdata.label.proposals import DEFAULT_RULES
from sgdata.markdown import replace_block

ROOT = Path(__file__).resolve().parents[1]
LABELS = ROOT / "tests/sgdata/label/data"
DOC = ROOT / "docs/labeling.md"
BEGIN, END = "<!-- proposal-accuracy -->", "<!-- /proposal-accuracy -->"


def table() -> str:
    """The doc's block: what was scored, on which labels, and the table."""
    photos = {
        p.name[: -len(".json")]: PhotoLabels.model_validate_json(p.read_text(encoding="utf-8"))
        for p in sorted(LABELS.glob("*.json"))
    }
    lines = []
    for name, labels in photos.items():
        score = score_proposals({name: labels}, load_class_names(), DEFAULT_RULES)
        lines.append(f"- `{name}`: {score.agree} of {score.pairs} pairs ({score.accuracy:.0%})")
    total = score_proposals(photos, load_class_names(), DEFAULT_RULES)
    return "\n".join(
        [
            f"Proposals with the default rules against hand labels of {len(photos)} photos "
            f"({sum(len(p.objects) for p in photos.values())} boxes; "
            "`tests/sgdata/label/data/`), written by `python bench/label_proposals.py --write`:",
            "",
            *lines,
            "",
            total.table(),
        ]
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--write", action="store_true", help="replace the table in the doc")
    args = parser.parse_args()
    text = table()
    if not args.write:
        print(text)
        return
    try:
        doc = replace_block(DOC.read_text(encoding="utf-8"), BEGIN, END, text)
    except SgdataError as error:
        raise SystemExit(f"{DOC}: {error}") from None
    DOC.write_text(doc, encoding="utf-8")
    print(f"wrote the table in {DOC} (at commit {ProcessState.capture(ROOT).commit[:7]})")


if __name__ == "__main__":
    main()
