"""A picture of a cosserat run drawn by ParaView, the cloth coloured by one of its fields
(docs/output.md "Fields", docs/paraview.md).

    pvpython tools/paraview_render.py RUN.xmf [--field F] [--frame N | --time T]
                                      [-o OUT.png] [--size W H] [--elev E] [--azim A]

Opens the run's XDMF file with ParaView's Xdmf3 reader, as the GUI does, shows the frame
(default: the last) coloured by F (curvature by default; velocity is drawn as its length), and
saves a screenshot, by default RUN_F.png beside the run. Without a display, run it on a
virtual X server (Debian's xvfb) with a 24-bit screen that does not reset between clients:
`xvfb-run -a -s "-screen 0 1280x1024x24 -noreset" pvpython tools/paraview_render.py ...`
(docs/paraview.md says why). Exit status 2,
with one line naming what is wrong, for a file that is missing or not a run, a field the file
does not hold or a frame it lacks; nothing is written then.
"""

import argparse
import math
import os
import sys

# A running simulation holds a lock on its output; reading without HDF5's own lock lets a
# frame of a run in progress be drawn (the writer flushes whole frames).
os.environ.setdefault("HDF5_USE_FILE_LOCKING", "FALSE")

import numpy as np  # noqa: E402
from paraview import servermanager  # noqa: E402
from paraview import simple  # noqa: E402
from vtkmodules.numpy_interface import dataset_adapter  # noqa: E402


class InputError(Exception):
    """Bad input: exit status 2."""


# How each field of `cosserat run` is coloured: its label with units, ParaView's colour map, and
# whether it is centred on a neutral value (stretch against compression, bending either way).
FIELDS = {
    "curvature": ("mean curvature H (1/m)", "Cool to Warm", 0.0),
    "area_ratio": ("area ratio (rest = 1)", "Cool to Warm", 1.0),
    "energy_density": ("stored energy density (J/m²)", "Inferno (matplotlib)", None),
    "velocity": ("speed (m/s)", "Plasma (matplotlib)", None),
}
# A held corner or a loaded node makes a spike that would wash out the rest of the sheet: the
# colour range stops at this percentile of the frame's values (render.py does the same).
PERCENTILE = 99.0
CLOTH_COLOUR = [0.23, 0.49, 0.85]
SOLID_COLOUR = [0.62, 0.62, 0.62]


def parse_arguments(argv):
    parser = argparse.ArgumentParser(
        prog="paraview_render.py",
        description="Draw a frame of a cosserat run (its .xmf file) with ParaView, coloured "
                    "by a field, and save it as a PNG.")
    parser.add_argument("xmf", help="the run's XDMF file (written beside its .h5)")
    parser.add_argument("--field", default="curvature", choices=[*FIELDS, "none"],
                        help="what colours the cloth (default curvature)")
    which = parser.add_mutually_exclusive_group()
    which.add_argument("--frame", type=int,
                       help="frame index, negative from the end (default: the last)")
    which.add_argument("--time", type=float, help="the frame nearest this simulated time (s)")
    parser.add_argument("-o", "--output", help="PNG to write (default: RUN_FIELD.png)")
    parser.add_argument("--size", type=int, nargs=2, default=[1280, 960], metavar=("W", "H"),
                        help="picture size in pixels (default 1280 960)")
    parser.add_argument("--elev", type=float,
                        help="camera elevation, degrees (default: from the sheet's shape)")
    parser.add_argument("--azim", type=float,
                        help="camera azimuth about world y, degrees (default: from the sheet's "
                             "shape)")
    arguments = parser.parse_args(argv)
    if min(arguments.size) < 16:
        parser.error("--size must be at least 16 16")
    return arguments


def frame_time(times, frame, time):
    """The simulated time of the frame `--frame` or `--time` names (default: the last)."""
    if time is not None:
        if not times[0] - 1e-12 <= time <= times[-1] + 1e-12:
            raise InputError(f"--time {time}: the run holds t = {times[0]} to {times[-1]} s")
        return min(times, key=lambda t: abs(t - time))
    index = len(times) - 1 if frame is None else frame
    if index < 0:
        index += len(times)
    if not 0 <= index < len(times):
        raise InputError(f"no frame {frame}; the run holds {len(times)} "
                         f"(0 to {len(times) - 1}, or -1 to -{len(times)})")
    return times[index]


def cloth_arrays(reader, time, field):
    """The cloth's node positions [N, 3] and the field's values [N] (the velocity's length) at
    `time`. A run with solids is a collection of the cloth's grid and one surface per solid;
    the cloth is the block that is a structured grid."""
    data = servermanager.Fetch(reader)
    blocks = [data]
    if data.IsA("vtkMultiBlockDataSet") or data.IsA("vtkDataObjectTree"):
        iterator = data.NewIterator()
        iterator.InitTraversal()
        blocks = []
        while not iterator.IsDoneWithTraversal():
            blocks.append(iterator.GetCurrentDataObject())
            iterator.GoToNextItem()
    for block in blocks:
        if block is not None and block.IsA("vtkStructuredGrid"):
            wrapped = dataset_adapter.WrapDataObject(block)
            points = np.asarray(wrapped.Points)
            if field == "none":
                return points, None
            values = np.asarray(wrapped.PointData[field])
            if values.ndim == 2:
                values = np.linalg.norm(values, axis=1)
            return points, values
    raise InputError("the file holds no structured grid: is it the XDMF file of a cosserat run?")


def sheet_normal(points):
    """The unit normal of the plane that best fits the nodes (least squares)."""
    centred = points - points.mean(axis=0)
    return np.linalg.svd(centred, full_matrices=False)[2][2]


def camera_angles(points, elev, azim):
    """Elevation and azimuth (degrees; world y is up) that look at the sheet's face, as
    render.py chooses them: a sheet that lies flat is seen from 35 degrees up, one that stands
    35 degrees off its normal from 20 degrees up. Given angles are kept."""
    normal = sheet_normal(points)
    standing = math.hypot(normal[0], normal[2]) > 0.5
    if elev is None:
        elev = 20.0 if standing else 35.0
    if azim is None:
        azim = math.degrees(math.atan2(normal[0], normal[2])) + 35.0 if standing else 30.0
    return elev, azim


def place_camera(view, points, elev, azim):
    centre = 0.5 * (points.min(axis=0) + points.max(axis=0))
    up, around = math.radians(elev), math.radians(azim)
    towards = np.array([math.cos(up) * math.sin(around), math.sin(up),
                        math.cos(up) * math.cos(around)])
    view.CameraFocalPoint = centre.tolist()
    view.CameraPosition = (centre + towards).tolist()
    view.CameraViewUp = [0.0, 1.0, 0.0]
    # Fitted to the cloth: a floor is drawn twice the sheet's size.
    low, high = points.min(axis=0), points.max(axis=0)
    view.ResetCamera([low[0], high[0], low[1], high[1], low[2], high[2]], False)


def colour_range(values, centre):
    """The colour scale's limits: to the PERCENTILE-th value, symmetric about `centre` when
    the field has one."""
    finite = values[np.isfinite(values)]
    if finite.size == 0:
        return 0.0, 1.0
    if centre is not None:
        reach = float(np.percentile(np.abs(finite - centre), PERCENTILE)) or 1.0
        return centre - reach, centre + reach
    low, high = float(finite.min()), float(np.percentile(finite, PERCENTILE))
    return low, high if high > low else low + 1.0


def render(arguments):
    xmf = os.path.abspath(arguments.xmf)
    if not os.path.isfile(xmf):
        raise InputError(f"{arguments.xmf}: no such file")
    # The Xdmf3 readers join a relative file name's empty folder to the HDF5 file's name
    # ("run.xmfrun.h5"): they are given an absolute path. Reader T, because with solids Reader
    # S makes the cloth and the solids pieces of one dataset, which ParaView 5.11 then colours
    # by no field at all; T keeps them separate blocks.
    reader = simple.Xdmf3ReaderT(FileName=[xmf])
    reader.UpdatePipelineInformation()
    # One frame's time comes as a number, several as a list, none as an empty list.
    steps = reader.TimestepValues
    times = [float(steps)] if isinstance(steps, (int, float)) else list(steps) or [0.0]
    time = frame_time(times, arguments.frame, arguments.time)
    reader.UpdatePipeline(time)
    if arguments.field != "none" and arguments.field not in reader.PointData.keys():
        held = ", ".join(sorted(reader.PointData.keys())) or "none"
        raise InputError(f"{arguments.xmf} has no field '{arguments.field}' (it holds: {held}); "
                         "cosserat run writes the fields named by output.fields "
                         "(docs/output.md)")
    points, values = cloth_arrays(reader, time, arguments.field)

    view = simple.CreateView("RenderView")
    view.ViewSize = list(arguments.size)
    view.ViewTime = time
    view.Background = [1.0, 1.0, 1.0]
    if hasattr(view, "UseColorPaletteForBackground"):
        view.UseColorPaletteForBackground = 0
    view.OrientationAxesVisibility = 1
    display = simple.Show(reader, view)
    display.Representation = "Surface"
    if arguments.field == "none":
        display.ColorArrayName = ["POINTS", ""]
        display.AmbientColor = display.DiffuseColor = CLOTH_COLOUR
    else:
        label, colour_map, centre = FIELDS[arguments.field]
        if arguments.field == "velocity":
            simple.ColorBy(display, ("POINTS", "velocity", "Magnitude"))
        else:
            simple.ColorBy(display, ("POINTS", arguments.field))
        table = simple.GetColorTransferFunction(arguments.field)
        table.ApplyPreset(colour_map, True)
        # The solids of a contact scene hold no field: they take this colour.
        table.NanColor = SOLID_COLOUR
        low, high = colour_range(values, centre)
        table.RescaleTransferFunction(low, high)
        table.AutomaticRescaleRangeMode = "Never"
        display.SetScalarBarVisibility(view, True)
        bar = simple.GetScalarBar(table, view)
        bar.Title = label
        bar.ComponentTitle = ""
        bar.TitleColor = bar.LabelColor = [0.0, 0.0, 0.0]
    elev, azim = camera_angles(points, arguments.elev, arguments.azim)
    place_camera(view, points, elev, azim)
    title = simple.Text(Text=f"t = {time:.4g} s")
    title_display = simple.Show(title, view)
    title_display.WindowLocation = "Upper Left Corner"
    title_display.Color = [0.0, 0.0, 0.0]
    title_display.FontSize = 14

    output = arguments.output or (os.path.splitext(arguments.xmf)[0] + f"_{arguments.field}.png")
    simple.SaveScreenshot(output, view, ImageResolution=list(arguments.size))
    # A view left to the interpreter's exit loses its GL context after the X connection
    # (GLXBadContext under xvfb-run, exit status 1 after the picture was written).
    simple.Delete(view)
    return output


def main(argv):
    arguments = parse_arguments(argv)
    try:
        print(render(arguments))
    except InputError as error:
        print(f"error: {error}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
