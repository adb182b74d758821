"""Results kept as JSON files: a dataclass whose fields are the file's keys."""
import json
from dataclasses import fields
from pathlib import Path


class JsonFile:
    """For a dataclass kept as a JSON file of its fields (locate.json, compare.json): `of` a dict,
    `read` a file, `to_json` the file's content."""

    @classmethod
    def of(cls, data):
        """From the file's content (a dict)."""
        return cls(**{f.name: data[f.name] for f in fields(cls)})

    @classmethod
    def read(cls, path):
        """A file read back."""
        return cls.of(json.loads(Path(path).read_text(encoding="utf-8")))

    def to_json(self):
        """The file's content: each field under its name."""
        return {f.name: getattr(self, f.name) for f in fields(self)}
