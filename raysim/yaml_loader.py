"""Bounded, strict YAML reading for hand-written input files (scenarios, the thesis's files).

``yaml.safe_load`` trusts its input's size: a few hundred bytes of nested aliases (a
"billion laughs" file) expand to more nodes than any machine holds once raysim walks them,
20,000 nested brackets overflow Python's stack, and a key given twice silently keeps the last
value. :func:`parse_yaml` composes with :class:`BoundedLoader` instead, which refuses, while it
composes and so before any expansion:

- a key given twice in one mapping (naming both lines);
- more than :data:`MAX_NODES` nodes counted with every alias expanded;
- more than :data:`MAX_ALIASES` alias uses, and an alias inside the node it names (a loop);
- nesting deeper than :data:`MAX_DEPTH` levels;
- a timestamp that no ``datetime`` holds (year 0, month 13, before year 1 in UTC).

Everything is reported as :class:`raysim.errors.InputError` ``(file, "line N", what)``.
Valid files load exactly as with ``yaml.safe_load`` (same safe constructors and resolver).
"""

from __future__ import annotations

from pathlib import Path

import yaml
from yaml.composer import Composer, ComposerError
from yaml.constructor import ConstructorError, SafeConstructor
from yaml.events import AliasEvent, MappingEndEvent, ScalarEvent, SequenceEndEvent
from yaml.nodes import MappingNode, ScalarNode, SequenceNode
from yaml.resolver import Resolver

from raysim.errors import InputError
from raysim.input_files import read_text_file

try:  # libyaml's event parser when built in (about 5 x faster); the same events otherwise
    from yaml.cyaml import CParser as _Parser
except ImportError:  # pragma: no cover - PyYAML without libyaml
    from yaml.parser import Parser as _Parser
    from yaml.reader import Reader as _Reader
    from yaml.scanner import Scanner as _Scanner
else:
    _Reader = _Scanner = None

#: Nodes of one document with every alias expanded. The committed scenarios have a few hundred;
#: 1,000 objects of :data:`raysim.limits.MAX_OBJECTS` with all their keys stay below 60,000.
MAX_NODES = 100_000
#: Alias uses (``*name``) in one document.
MAX_ALIASES = 10_000
#: Nesting depth of mappings and sequences (a scenario is at most 6 deep).
MAX_DEPTH = 100
#: Largest scenario file read, bytes (the committed ones are under 10 kB).
MAX_FILE_BYTES = 16_000_000


class LimitError(yaml.MarkedYAMLError):
    """A bound of :class:`BoundedLoader` was passed, at ``problem_mark`` (its column too if ``with_column``)."""

    with_column = False


class BoundedComposer(Composer):
    """PyYAML's composer with duplicate-key, size, alias and depth checks (see the module)."""

    def __init__(self) -> None:
        super().__init__()
        self._expanded_nodes = 0  # nodes so far, aliases expanded
        self._aliases = 0
        self._depth = 0
        self._open: set[int] = set()  # ids of the collections being composed
        self._sizes: dict[int, int] = {}  # expanded size of each anchored node

    def _count(self, n_nodes: int, mark) -> None:
        self._expanded_nodes += n_nodes
        if self._expanded_nodes > MAX_NODES:
            raise LimitError(problem=f"more than {MAX_NODES:,} YAML nodes (aliases expanded); a scenario needs "
                             "a few hundred (long tracks belong in a trajectory CSV)", problem_mark=mark)

    def _alias(self):
        event = self.get_event()
        node = self.anchors.get(event.anchor)
        if node is None:
            raise ComposerError(None, None, f"found undefined alias {event.anchor!r}", event.start_mark)
        if id(node) in self._open:
            raise LimitError(problem=f"alias *{event.anchor} is used inside the node it names (a loop)",
                             problem_mark=event.start_mark)
        self._aliases += 1
        if self._aliases > MAX_ALIASES:
            raise LimitError(problem=f"more than {MAX_ALIASES:,} alias uses (*name)", problem_mark=event.start_mark)
        self._count(self._sizes.get(id(node), 1), event.start_mark)
        return node

    def compose_node(self, parent, index):
        """Compose one node, counting it (and an alias's whole expansion) against the bounds."""
        if self.check_event(AliasEvent):
            return self._alias()
        event = self.peek_event()
        self._count(1, event.start_mark)
        before = self._expanded_nodes - 1
        if not self.check_event(ScalarEvent):
            self._depth += 1
            if self._depth > MAX_DEPTH:
                raise LimitError(problem=f"nested deeper than {MAX_DEPTH} levels", problem_mark=event.start_mark)
        try:
            node = super().compose_node(parent, index)
        finally:
            if not isinstance(event, ScalarEvent):
                self._depth -= 1
        if event.anchor is not None:
            self._sizes[id(node)] = self._expanded_nodes - before
        return node

    def compose_sequence_node(self, anchor):
        """A sequence, open (for the alias-loop check) while its items are composed."""
        start_event = self.get_event()
        tag = start_event.tag
        if tag is None or tag == "!":
            tag = self.resolve(SequenceNode, None, start_event.implicit)
        node = SequenceNode(tag, [], start_event.start_mark, None, flow_style=start_event.flow_style)
        if anchor is not None:
            self.anchors[anchor] = node
        self._open.add(id(node))
        index = 0
        while not self.check_event(SequenceEndEvent):
            node.value.append(self.compose_node(node, index))
            index += 1
        self._open.discard(id(node))
        node.end_mark = self.get_event().end_mark
        return node

    def compose_mapping_node(self, anchor):
        """A mapping whose scalar keys are unique: a key given twice names both lines."""
        start_event = self.get_event()
        tag = start_event.tag
        if tag is None or tag == "!":
            tag = self.resolve(MappingNode, None, start_event.implicit)
        node = MappingNode(tag, [], start_event.start_mark, None, flow_style=start_event.flow_style)
        if anchor is not None:
            self.anchors[anchor] = node
        self._open.add(id(node))
        first_mark: dict[tuple[str, str], yaml.Mark] = {}
        while not self.check_event(MappingEndEvent):
            key = self.compose_node(node, None)
            if isinstance(key, ScalarNode):
                seen = first_mark.get((key.tag, key.value))
                if seen is not None:
                    raise _given_twice(key, seen)
                first_mark[(key.tag, key.value)] = key.start_mark
            node.value.append((key, self.compose_node(node, key)))
        self._open.discard(id(node))
        node.end_mark = self.get_event().end_mark
        return node


def _given_twice(key: ScalarNode, first) -> LimitError:
    """The error for ``key`` given a second time: its line and the first one's (columns on one line)."""
    mark = key.start_mark
    if first.line != mark.line:
        return LimitError(problem=f"key {key.value!r} given twice (first at line {first.line + 1})", problem_mark=mark)
    error = LimitError(problem=f"key {key.value!r} given twice (first at column {first.column + 1})", problem_mark=mark)
    error.with_column = True
    return error


class BoundedConstructor(SafeConstructor):
    """``SafeConstructor`` whose timestamps that no ``datetime`` holds are YAML errors, not crashes."""

    def construct_yaml_timestamp(self, node):
        try:
            return super().construct_yaml_timestamp(node)
        except (ValueError, OverflowError) as exc:
            raise ConstructorError(None, None, f"not a valid time {node.value!r} ({exc})", node.start_mark) from None


BoundedConstructor.add_constructor("tag:yaml.org,2002:timestamp", BoundedConstructor.construct_yaml_timestamp)


if _Reader is None:

    class BoundedLoader(_Parser, BoundedComposer, BoundedConstructor, Resolver):
        """libyaml's parser, the bounded composer, safe constructors, the standard resolver."""

        def __init__(self, stream):
            _Parser.__init__(self, stream)
            BoundedComposer.__init__(self)
            BoundedConstructor.__init__(self)
            Resolver.__init__(self)

        get_single_node = BoundedComposer.get_single_node
        compose_document = BoundedComposer.compose_document
        compose_node = BoundedComposer.compose_node

else:  # pragma: no cover - PyYAML without libyaml

    class BoundedLoader(_Reader, _Scanner, _Parser, BoundedComposer, BoundedConstructor, Resolver):
        """PyYAML's pure-Python reader, scanner and parser with the bounded composer."""

        def __init__(self, stream):
            _Reader.__init__(self, stream)
            _Scanner.__init__(self)
            _Parser.__init__(self)
            BoundedComposer.__init__(self)
            BoundedConstructor.__init__(self)
            Resolver.__init__(self)


def parse_yaml(text: str, file: str) -> object:
    """Parse one YAML document with :class:`BoundedLoader`.

    Parameters
    ----------
    text : str
        The document.
    file : str
        Its name, for messages.

    Raises
    ------
    InputError
        ``(file, "line N, column M" or "line N", what)`` for invalid YAML and every bound.
    """
    loader = BoundedLoader(text)
    try:
        return loader.get_single_data()
    except LimitError as exc:
        mark = exc.problem_mark
        where = f"line {mark.line + 1}" + (f", column {mark.column + 1}" if exc.with_column else "")
        raise InputError(file, where, exc.problem) from None
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        where = f"line {mark.line + 1}, column {mark.column + 1}" if mark else "(file)"
        raise InputError(file, where, f"not valid YAML: {exc.problem or exc.context}") from None
    except yaml.YAMLError as exc:
        raise InputError(file, "(file)", f"not valid YAML: {exc}") from None
    except RecursionError:  # a bound above should come first; never a traceback
        raise InputError(file, "(file)", f"nested too deeply (at most {MAX_DEPTH} levels)") from None
    finally:
        loader.dispose()


def read_yaml(path: Path) -> object:
    """Read and parse a YAML input file; any problem is an :class:`InputError` naming the place.

    The file must be a regular file (not a FIFO, socket, device or symlink loop: checked without
    blocking), UTF-8, not empty and at most :data:`MAX_FILE_BYTES` long.
    """
    path = Path(path)
    text = read_text_file(path, str(path), "(file)", MAX_FILE_BYTES, kind="scenario file")
    if not text.strip():
        raise InputError(str(path), "(file)", "file is empty")
    return parse_yaml(text, str(path))
