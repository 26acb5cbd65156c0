"""The README's scene example is a valid scene (the documentation cannot rot)."""
from pathlib import Path

import yaml

from fmt import scene

README = Path(__file__).resolve().parents[2] / "README.md"


def test_readme_scene_example_parses():
    text = README.read_text()
    block = text[text.index("```yaml\n") + 8:]
    block = block[:block.index("```")]
    sc = scene.Scene.from_dict(yaml.safe_load(block))
    truth = sc.truth(0.0003)                       # the second tap interval is not active yet
    names = {t["name"] for t in truth}
    assert names == {"still", "drag", "taps"}
    assert {t["name"] for t in sc.truth(0.0005)} == {"still", "drag"}
