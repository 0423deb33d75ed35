"""``vtool presets list | show NAME | copy NAME DEST``."""

from __future__ import annotations

from pathlib import Path

import click

from vtool.errors import InputError
from vtool.files import check_output_path, exists, is_dir, write_atomic
from vtool.presets import find_preset, list_presets, self_contained_text


@click.group()
def presets() -> None:
    """List, show and copy the shipped presets."""


@presets.command("list")
def list_command() -> None:
    """List shipped presets: name, kind and title."""
    infos = list_presets()
    width = max((len(i.name) for i in infos), default=4)
    for info in infos:
        click.echo(f"{info.name:<{width}}  {info.kind:<11} {info.title}")


@presets.command("show")
@click.argument("name")
def show_command(name: str) -> None:
    """Print a preset's TOML text."""
    click.echo(find_preset(name).read_text(encoding="utf-8"), nl=False)


@presets.command("copy")
@click.argument("name")
@click.argument("dest", type=click.Path(dir_okay=True, path_type=Path))
@click.option("--force", is_flag=True, help="Overwrite an existing file.")
def copy_command(name: str, dest: Path, force: bool) -> None:
    """Copy a preset to DEST (a file, or a folder to copy into) to edit it."""
    if not is_dir(dest):
        check_output_path(dest, "DEST")  # before any work
    source = find_preset(name)
    target = dest / source.name if is_dir(dest) else dest
    check_output_path(target, "DEST")
    if exists(target) and not force:
        raise InputError("dest", str(target), "a path that does not exist yet (or --force)")
    text, note = self_contained_text(source)  # a lift-table file is written in: the copy loads anywhere
    write_atomic(target, text, "DEST")
    click.echo(f"copied {source.stem} to {target}" + (f" ({note})" if note else ""))


@presets.command("expand")
@click.argument("name")
def expand_command(name: str) -> None:
    """Print a train-type preset ([train] type = ...) as the explicit model it expands to
    (coordinates, members, clearances, cam, follower); an explicit preset prints unchanged."""
    import tomli_w

    from vtool.presets import read_document
    from vtool.presets.trains import expand

    path = find_preset(name)
    doc = read_document(path)
    if "train" not in doc:
        click.echo(path.read_text(encoding="utf-8"), nl=False)
        return
    explicit = expand(doc, path.parent)
    click.echo(f"# {path.stem}: the explicit model of its [train] (vtool presets expand; presets/trains.py)")
    if explicit.get("springs"):
        from vtool.presets.springs import describe_document

        for line in describe_document(explicit):
            click.echo(f"# {line}")
    click.echo(tomli_w.dumps(explicit), nl=False)
