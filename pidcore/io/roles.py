"""Which channel is the drive force, the velocity and the acceleration of a measurement.

Rules, in order, for each role not named by the user:

1. Channels whose quantity (from their unit) is the role's quantity. One -> taken. Several ->
   those whose name also says the role (``"Force"``, ``"Kraft"``, ``"LDV"``, ``"acc"``, ...);
   if that does not leave exactly one, :class:`ChannelError` names the candidates and the option
   to choose (``--force NAME``).
2. No channel of that quantity: channels of quantity ``"unknown"`` (no or unrecognised unit)
   whose name says the role; their values are taken as SI. Several -> ambiguous, as above.

Explicit names (``force=``, ``velocity=``, ``acceleration=``) override detection. A named
channel must exist (else the error lists the channels) and must be of the role's quantity or
of quantity ``"unknown"`` (the analysis then asks for its unit); a channel of another known
quantity (``--force`` naming an acceleration channel) is refused, unless its unit is given
for the role (``retyped``: ``--force NAME --force-unit N`` for a force exported under a wrong
unit).

A force channel and at least one of velocity or acceleration are required. An acceleration
channel is only looked for when it is needed: as the motion when there is no velocity, or for
mass cancellation (``mass_cancellation=True``), where it must be the acceleration *at the drive
point*: with several acceleration channels, or one named like a reference or shaker
accelerometer (``"Ref"``, ``"Shaker"``, ``"Table"``, ...), it must be named. Channels no role
uses are listed in :attr:`RoleAssignment.ignored`.

A channel detected by its unit whose name says another role (``Velocity [N]``) is used as its
unit says, and :attr:`RoleAssignment.notes` says so: the unit scales the numbers, the name is
free text. Such a channel that no role uses (a ``Velocity [g]`` beside an acceleration channel)
is noted too: the quantity its name says was never read. Where the unit leaves a role its name
says empty, the refusal names the column.
"""

from __future__ import annotations

import re
from collections.abc import Collection
from dataclasses import dataclass

from ..errors import ChannelError, a_or_an, listed
from ..records import Channel, Measurement
from ..units import read_unit

_NAME_TOKENS = {
    "force": {"force", "f", "fz", "kraft", "load", "forcecell", "loadcell"},
    "velocity": {"vel", "velocity", "v", "vz", "ldv", "vibrometer", "laser", "speed",
                 "geschwindigkeit", "schnelle"},
    "acceleration": {"acc", "accel", "acceleration", "accelerometer", "a", "az",
                     "beschleunigung"},
}
_NAME_PREFIXES = {
    "force": ("force", "kraft"),
    "velocity": ("veloc", "vibrom", "ldv"),
    "acceleration": ("accel", "acc", "beschl"),
}
#: The keyword of AnalysisOptions naming each role's channel, as a message says it.
_OPTIONS = {"force": "force=", "velocity": "velocity=", "acceleration": "acceleration="}
#: Name tokens of accelerometers that are not at the drive point.
_REFERENCE_TOKENS = {"ref", "reference", "shaker", "table", "armature", "base", "control",
                     "ctrl", "fixture", "slip", "head", "kopf", "referenz"}


def is_reference_name(name: str) -> bool:
    """Whether a channel name says a reference/shaker accelerometer (``"Ref acc"``).

    >>> is_reference_name("Shaker table acc"), is_reference_name("Acc drive point")
    (True, False)
    """
    tokens = re.findall(r"[a-zäöüß]+", name.lower())
    return any(t in _REFERENCE_TOKENS or t.startswith("ref") for t in tokens)


@dataclass(frozen=True)
class RoleAssignment:
    """Channels playing the roles of a power analysis.

    Attributes
    ----------
    force : Channel
        Drive force, N.
    velocity : Channel or None
        Drive-point velocity, m/s.
    acceleration : Channel or None
        Drive-point acceleration, m/s^2.
    ignored : tuple of str
        Names of the channels no role uses.
    notes : tuple of str
        What the output must say: a channel taken for a role by its unit while its name says
        another role (``"Velocity [N]"`` used as the force), or left unused so (``"Velocity
        [g]"`` beside the acceleration used).
    """

    force: Channel
    velocity: Channel | None
    acceleration: Channel | None
    ignored: tuple[str, ...] = ()
    notes: tuple[str, ...] = ()


def name_suggests(name: str, role: str) -> bool:
    """Whether a channel name says ``role`` (``"Drive point force"`` -> force).

    >>> name_suggests("Acc 1", "acceleration"), name_suggests("1+Z", "force")
    (True, False)
    """
    tokens = re.findall(r"[a-zäöüß]+", name.lower())
    if any(t in _NAME_TOKENS[role] for t in tokens):
        return True
    return any(t.startswith(_NAME_PREFIXES[role]) for t in tokens if len(t) > 2)


def _role_of_the_name(channel: Channel, role: str) -> str | None:
    """The one other role ``channel``'s name says where its unit says ``role`` (``"Velocity"``
    in N -> ``"velocity"``), else None."""
    said = [r for r in _OPTIONS if name_suggests(channel.name, r)]
    return said[0] if len(said) == 1 and said[0] != role else None


def _unit_over_name_note(source: str, channel: Channel, role: str) -> str | None:
    """The note that a channel detected by its unit is used against what its name says: a
    column 'Velocity [N]' was used as the force without a word."""
    named = _role_of_the_name(channel, role)
    if named is None or channel.quantity != role:
        return None
    said, remedy = _name_against_unit(channel, named)
    return (f"{source}: channel {said}: used as the {role}, as its unit says (the unit scales "
            f"its numbers; a name is free text); {remedy}")


def _name_against_unit(channel: Channel, named: str) -> tuple[str, str]:
    """(``"'Velocity' is named like a velocity but its unit 'N' is a force unit"``, ``"if it
    is the velocity, name it with velocity='Velocity' and give its unit with
    velocity_unit=UNIT"``): the words every note and refusal of a channel whose name says the
    role ``named`` and whose unit another quantity gives it."""
    return (f"{channel.name!r} is named like {a_or_an(named)} but its unit "
            f"{channel.source_unit or channel.unit!r} is {a_or_an(channel.quantity)} unit",
            f"if it is the {named}, name it with {_OPTIONS[named]}{channel.name!r} and give "
            f"its unit with {named}_unit=UNIT")


def _misnamed_hint(measurement: Measurement, roles: tuple[str, ...],
                   taken: set[str]) -> str:
    """`` ('Velocity' is named like a velocity but its unit 'N' is a force unit: ...)`` for an
    unused channel whose name says one of ``roles`` but whose unit another quantity: "no
    velocity channel" of a file with a column 'Velocity [N]' did not say why it was not one."""
    for channel in measurement.channels:
        if channel.name in taken or channel.quantity in ("unknown", *roles):
            continue
        named = [r for r in roles if _role_of_the_name(channel, channel.quantity) == r]
        if named:
            said, remedy = _name_against_unit(channel, named[0])
            return f" ({said}: {remedy})"
    return ""


def _unused_against_name_note(source: str, channel: Channel) -> str | None:
    """The note that a channel no role uses has a name saying another role than its unit: a
    'Velocity [g]' beside an 'Acceleration [m/s^2]' was left out as "not needed" without a
    word that the velocity its name promises was never read (its unit said acceleration)."""
    if channel.quantity not in _OPTIONS:
        return None
    named = _role_of_the_name(channel, channel.quantity)
    if named is None:
        return None
    said, remedy = _name_against_unit(channel, named)
    return (f"{source}: channel {said}: not used (its unit makes it {a_or_an(channel.quantity)}, "
            f"its name {a_or_an(named)}: check which quantity it holds); {remedy}")


def _names(channels: list[Channel]) -> str:
    return listed(c.name for c in channels)


def _candidates(measurement: Measurement, role: str, taken: set[str]) -> list[Channel]:
    free = [c for c in measurement.channels if c.name not in taken]
    by_quantity = [c for c in free if c.quantity == role]
    if by_quantity:
        return by_quantity
    return [c for c in free if c.quantity == "unknown" and name_suggests(c.name, role)]


def _drive_point_acceleration(measurement: Measurement, taken: set[str],
                              why: str) -> Channel | None:
    found = _candidates(measurement, "acceleration", taken)
    if len(found) > 1:
        raise ChannelError(f"{measurement.source}: {len(found)} acceleration channels "
                           f"({_names(found)}); {why} needs the acceleration at the drive point:"
                           " choose it with acceleration=NAME")
    if found and is_reference_name(found[0].name):
        raise ChannelError(f"{measurement.source}: the only acceleration channel "
                           f"{found[0].name!r} is named like a reference/shaker accelerometer; "
                           f"{why} needs the acceleration at the drive point: confirm it with "
                           f"acceleration={found[0].name!r} or remove the option")
    if not found:
        _refuse_a_refused_unit_of(measurement, "acceleration",
                                  [c for c in measurement.channels if c.name not in taken])
    return found[0] if found else None


def _detect(measurement: Measurement, role: str, taken: set[str]) -> Channel | None:
    free = [c for c in measurement.channels if c.name not in taken]
    by_quantity = [c for c in free if c.quantity == role]
    if len(by_quantity) == 1:
        return by_quantity[0]
    if len(by_quantity) > 1:
        named = [c for c in by_quantity if name_suggests(c.name, role)]
        if len(named) == 1:
            return named[0]
        raise ChannelError(f"{measurement.source}: {len(by_quantity)} {role} channels "
                           f"({_names(by_quantity)}); choose one with {_OPTIONS[role]}NAME")
    by_name = [c for c in free if c.quantity == "unknown" and name_suggests(c.name, role)]
    if len(by_name) == 1:
        return by_name[0]
    if len(by_name) > 1:
        raise ChannelError(f"{measurement.source}: {len(by_name)} channels look like {role} "
                           f"({_names(by_name)}); choose one with {_OPTIONS[role]}NAME")
    _refuse_a_refused_unit_of(measurement, role, free)
    return None


def _refuse_a_refused_unit_of(measurement: Measurement, role: str, free: list[Channel]) -> None:
    """Refuse a measurement whose only channel of ``role`` has a unit of that quantity which
    pidcore refuses (``Point1:+Z`` in ``Mm/s``): left out as of no unit, the analysis went on
    without it (another channel as the motion, or 'no velocity channel')."""
    for channel in free:
        reading = read_unit(channel.source_unit)
        if channel.quantity == "unknown" and reading.quantity == role and reading.problem:
            raise ChannelError(
                f"{measurement.source}: channel {channel.name!r} ({role}) has a unit pidcore "
                f"refuses: {reading.problem}; give it with {role}_unit=UNIT and name it with "
                f"{_OPTIONS[role]}{channel.name!r}")


def _named(measurement: Measurement, role: str, name: str, retyped: bool) -> Channel:
    channel = measurement.channel(name)  # ChannelError listing the channels there are
    if channel.quantity not in (role, "unknown") and not retyped:
        raise ChannelError(f"{measurement.source}: {_OPTIONS[role]}{name!r} is "
                           f"{a_or_an(channel.quantity)} channel "
                           f"({channel.source_unit or channel.unit}); expected {a_or_an(role)} "
                           "channel or one without a unit, or give its unit with "
                           f"{role}_unit=UNIT if the file's is wrong")
    return channel


def assign_roles(measurement: Measurement, *, force: str | None = None,
                 velocity: str | None = None, acceleration: str | None = None,
                 mass_cancellation: bool = False,
                 retyped: Collection[str] = ()) -> RoleAssignment:
    """Find the force, velocity and acceleration channels of ``measurement``.

    Parameters
    ----------
    measurement : Measurement
    force, velocity, acceleration : str, optional
        Channel names that override detection.
    mass_cancellation : bool
        The drive-point acceleration is needed (``--mass-below-gauge``): it is looked for
        although there is a velocity channel, and must be unambiguous.
    retyped : collection of str
        Roles whose unit the user gives (``--force-unit`` ...): a channel named for such a
        role may carry another quantity's unit (the file's unit is wrong).

    Returns
    -------
    RoleAssignment

    Raises
    ------
    ChannelError
        Unknown or unsuitable named channel, ambiguous detection, no force channel, or neither
        velocity nor acceleration.

    Examples
    --------
    >>> import numpy as np
    >>> from pidcore.records import Channel, Measurement
    >>> chans = (Channel("F", "force", np.zeros(4), 100.0),
    ...          Channel("LDV", "velocity", np.zeros(4), 100.0))
    >>> assign_roles(Measurement("demo.csv", chans)).velocity.name
    'LDV'
    """
    explicit = {"force": force, "velocity": velocity, "acceleration": acceleration}
    chosen: dict[str, Channel | None] = {}
    for role, name in explicit.items():
        if name is not None:
            chosen[role] = _named(measurement, role, name, role in retyped)
    taken = {c.name for c in chosen.values() if c is not None}
    repeated = [r for r, c in chosen.items()
                if c is not None and sum(o is c for o in chosen.values()) > 1]
    if repeated:
        raise ChannelError(f"{measurement.source}: one channel named for several roles "
                           f"({', '.join(repeated)})")
    for role in ("force", "velocity", "acceleration"):
        if role not in chosen:
            if role == "acceleration" and chosen["velocity"] is not None:
                # not needed as the motion: only for mass cancellation, at the drive point
                chosen[role] = (_drive_point_acceleration(measurement, taken,
                                                          "mass_below_gauge_kg")
                                if mass_cancellation else None)
            else:
                chosen[role] = _detect(measurement, role, taken)
                if role == "acceleration" and chosen[role] is not None and \
                        is_reference_name(chosen[role].name):
                    raise ChannelError(
                        f"{measurement.source}: no velocity channel and the acceleration "
                        f"channel {chosen[role].name!r} is named like a reference/shaker "
                        f"accelerometer; confirm it with acceleration={chosen[role].name!r}")
            if chosen[role] is not None:
                taken.add(chosen[role].name)
        if role == "force" and chosen["force"] is None:
            # Checked before the other roles: a missing force is the more basic problem.
            raise ChannelError(f"{measurement.source}: no force channel among "
                               f"{_names(list(measurement.channels))}"
                               f"{_misnamed_hint(measurement, ('force',), taken)}; name one "
                               "with force=NAME")
    if chosen["velocity"] is None and chosen["acceleration"] is None:
        raise ChannelError(f"{measurement.source}: no velocity or acceleration channel among "
                           f"{_names(list(measurement.channels))}"
                           f"{_misnamed_hint(measurement, ('velocity', 'acceleration'), taken)}"
                           "; name one with velocity=NAME or acceleration=NAME")
    used = {c.name for c in chosen.values() if c is not None}
    ignored = [c for c in measurement.channels if c.name not in used]
    notes = [*(_unit_over_name_note(measurement.source, channel, role)
               for role, channel in chosen.items()
               if channel is not None and explicit[role] is None),
             *(_unused_against_name_note(measurement.source, c) for c in ignored)]
    return RoleAssignment(force=chosen["force"], velocity=chosen["velocity"],
                          acceleration=chosen["acceleration"],
                          ignored=tuple(c.name for c in ignored),
                          notes=tuple(note for note in notes if note))
