"""Which surface gets which texture: room structure by room type, objects by class and part.

An object's *body* (every part drawn in a palette colour) takes its class's texture; parts in
the shared secondary colours of the recipes keep a texture of their own whatever the class
(metal fittings stay metal, screens and glass stay smooth). Classes not listed (a user's
class file) get :data:`DEFAULT_TEXTURE`. Texture kinds are defined in
:mod:`sgdata.world.textures`.
"""

from __future__ import annotations

from sgdata.world.shapes.base import DARK, GLASS, METAL, WHITE, Color

__all__ = [
    "CLASS_TEXTURES",
    "DEFAULT_TEXTURE",
    "FLOOR_TEXTURES",
    "PART_TEXTURES",
    "STRUCTURE_TEXTURES",
    "body_texture",
    "part_texture",
    "structure_texture",
]

DEFAULT_TEXTURE = "matte"

# The floor by room type (wet rooms tiled, like their flat colours in usd/room_io.py).
FLOOR_TEXTURES = {"kitchen": "tiles", "bathroom": "tiles", "living_room": "wood", "bedroom": "wood"}
# The other structure meshes, by prim name under /Room/Structure.
STRUCTURE_TEXTURES = {"Walls": "plaster", "Ceiling": "plaster"}


def _classes(kind: str, names: str) -> dict[str, str]:
    return dict.fromkeys(names.split(), kind)


CLASS_TEXTURES: dict[str, str] = {
    **_classes(
        "wood",
        "Cabinet Drawer Shelf ShelvingUnit DiningTable SideTable CoffeeTable TVStand Desk "
        "Dresser Stool Chair Sink Pencil PictureFrame",
    ),
    **_classes(
        "metal",
        "Fridge Stove StoveBurner StoveKnob Microwave Toaster CoffeeMachine Safe SinkBasin Pot "
        "Pan Kettle Knife Fork Spoon ButterKnife Ladle GarbageCan TowelHolder ToiletPaperHanger "
        "Laptop Watch KeyChain",
    ),
    **_classes(
        "fabric",
        "Sofa ArmChair Ottoman Bed DogBed Pillow LaundryHamper Towel HandTowel Cloth TeddyBear "
        "Clothes Blanket Backpack",
    ),
    **_classes(
        "smooth",
        "Toilet Bathtub BathtubBasin Mirror Window Television Desktop CellPhone RemoteControl "
        "Mug Cup Bowl Plate Vase Bottle WineBottle SoapBottle SprayBottle SaltShaker "
        "PepperShaker CreditCard Pen CD AlarmClock Candle SoapBar Plunger ScrubBrush "
        "LightSwitch GarbageBag DeskLamp FloorLamp VacuumCleaner Spatula Egg TennisRacket",
    ),
    **_classes(
        "matte",
        "CounterTop Painting RoomDecor HousePlant Apple Tomato Potato Lettuce Bread Book "
        "Newspaper Box TissueBox ToiletPaper PaperTowelRoll Statue BasketBall DishSponge Shoes",
    ),
}

# Parts in the recipes' shared secondary colours (sgdata.world.shapes.base), whatever the class.
PART_TEXTURES: dict[Color, str] = {METAL: "metal", DARK: "smooth", GLASS: "smooth", WHITE: "smooth"}
_PART_KEYS = {
    tuple(float(f"{c:.6g}") for c in color): kind for color, kind in PART_TEXTURES.items()
}


def body_texture(class_name: str) -> str:
    """The texture kind of a class's body (its palette-coloured parts)."""
    return CLASS_TEXTURES.get(class_name, DEFAULT_TEXTURE)


def part_texture(color: Color, body: str) -> tuple[str, bool]:
    """(texture kind, is body) of a part of colour ``color`` on an object whose body is ``body``.

    Colours are compared at float32 precision (as stored in USD), so a colour read back from
    a stage finds its part.
    """
    key = tuple(float(f"{float(c):.6g}") for c in color)
    kind = _PART_KEYS.get(key)  # type: ignore[arg-type]
    return (kind, False) if kind is not None else (body, True)


def structure_texture(name: str, room_type: str) -> str:
    """The texture kind of structure mesh ``name`` (Floor, Walls, Ceiling) of a room type."""
    if name == "Floor":
        return FLOOR_TEXTURES.get(room_type, "tiles")
    return STRUCTURE_TEXTURES.get(name, "plaster")
