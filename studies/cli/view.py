"""``rmt view``: the robot in its work cell, live in the browser (viser: three.js over a websocket, served
on localhost) — joint sliders with the tool pose, σ_min, the nearest obstacle and self pair and the
windows read out as they move, a handle on the tool that solves IK, path playback, reach targets
(:mod:`studies.view`).  viser is an optional extra (``pip install 'rmtkit[view]'``) imported only when
the command runs.  The server listens on 127.0.0.1 unless ``--host`` says otherwise; Ctrl-C stops it
(exit 0)."""
from __future__ import annotations

import errno
import signal
import socket
import sys

from studies.cli.common import EXIT_OK, EXIT_USAGE, CliInputError, bounded, cell_args, world_from_args
from studies.cli.floor import floor_from_args, sigma_floor_args

#: the default port (viser's)
DEFAULT_PORT = 8080
INSTALL_HINT = "rmt view needs viser: pip install 'rmtkit[view]'"


def _check_port(host: str, port: int) -> None:
    """Refuse a host:port that cannot be listened on (busy, not an address of this machine, not allowed)
    before any work — viser itself would move to the next free port without a word."""
    try:
        infos = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM)
    except socket.gaierror as e:
        raise CliInputError(f"--host {host}: not a host name or address this machine resolves ({e.strerror})") \
            from None
    family, _, _, _, addr = infos[0]
    with socket.socket(family, socket.SOCK_STREAM) as s:
        # as the server will: a port left in TIME_WAIT by a server just stopped is free, a listener is not
        s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            s.bind(addr)
            s.listen(1)
        except OSError as e:
            if e.errno == errno.EADDRNOTAVAIL:
                raise CliInputError(f"--host {host}: not an address of this machine ({e.strerror}); give one of its "
                                    "addresses (default 127.0.0.1)") from None
            why = "in use: another program listens there" if e.errno == errno.EADDRINUSE else (e.strerror or str(e))
            raise CliInputError(f"--port {port}: cannot listen on {host}:{port} ({why}); choose another with "
                                f"--port P (0: any free port)") from None


def cmd_view(args, load_robot) -> int:
    try:
        if getattr(args, "html", None) is None:      # --html writes a page: no server, no viser
            import viser  # noqa: F401 - only probes that the extra is installed
    except ImportError:
        print(f"rmt: error: {INSTALL_HINT}", file=sys.stderr)
        return EXIT_USAGE
    from studies.cli.common import windows_from_args
    from studies.cli.kinematics import configuration
    from studies.taskrows import require_task_rows
    from studies.view.readouts import LiveModel
    from studies.view.scene import initial_configuration
    robot = require_task_rows(load_robot(args.robot))
    if args.html is not None:
        from kin.output import check_output
        if not args.html.endswith(".html"):
            raise CliInputError(f"--html {args.html!r} must end in .html")
        check_output(args.html)
    elif args.port != 0:
        _check_port(args.host, args.port)
    args.self_collision = True                          # the robot against itself, always
    world = world_from_args(robot, args)
    ws = windows_from_args(robot, args.margin, args.sigma_min)
    floor = floor_from_args(robot, args)
    cell_meshes, frame = None, "base frame"
    if args.cell is not None:
        from planning.cell import load_cell
        from studies.cli.common import cell_file
        cell = load_cell(cell_file(args.cell))
        cell_meshes, frame = cell.meshes, "cell frame"
    timeline = study = None
    if args.path is not None:
        from studies.view.playback import path_timeline
        timeline = path_timeline(robot, args.path)
    elif args.trajectory is not None:
        from studies.view.playback import trajectory_timeline
        timeline = trajectory_timeline(robot, args.trajectory)
    notes = []
    if args.reach is not None:
        import numpy as np

        from planning.collision import collision_world
        from studies.view.targets import load_reach
        study = load_reach(args.reach, robot)
        if world is None:
            world = collision_world(robot, None, 0.0)
        if not np.allclose(world.base, study.placement, atol=1e-9):
            world.move_base(study.placement)
            notes.append("the robot stands where the reach study placed it (its placement differs from the cell's)")
    model = LiveModel(robot, world, ws, floor.active, floor.text, frame)
    q0 = configuration(robot, args.q, "--q") if args.q else None
    if q0 is None and timeline is not None:
        q0 = timeline.Q[0]
    if getattr(args, "html", None) is not None:
        return _write_html(args, robot, world, q0, timeline, study, cell_meshes)
    from studies.view.server import ViewServer
    try:
        view = ViewServer(model, initial_configuration(robot, q0), host=args.host, port=args.port,
                          cell_meshes=cell_meshes, timeline=timeline, study=study, notes=notes)
    except OSError as e:
        raise CliInputError(f"--port {args.port}: cannot listen on {args.host}:{args.port} ({e.strerror or e})") \
            from None
    if args.port != 0 and view.port != args.port:         # taken between the check and the start
        view.stop()
        raise CliInputError(f"--port {args.port}: {args.host}:{args.port} was taken; choose another with --port P")
    host = f"[{args.host}]" if ":" in args.host else args.host
    url = f"http://{host}:{view.port}"
    for text in view.notes[:1] + notes:
        print(f"note: {text}", file=sys.stderr)
    if args.json:
        from studies.jsonio import dump
        print(dump({"url": url, "host": args.host, "port": view.port, "robot": robot.name,
                    "cell": (world.name or args.cell) if args.cell else None, "notes": view.notes[:1] + notes}),
              flush=True)
    else:
        print(f"rmt view: {robot.name}{' in ' + (world.name or args.cell) if args.cell else ''} at {url} "
              "(Ctrl-C stops)", flush=True)
    if not args.no_browser:
        import webbrowser
        try:
            opened = webbrowser.open(url)
        except Exception:                                 # a broken browser setting: the URL is printed
            opened = False
        if not opened:
            print(f"note: no web browser found; open {url} yourself", file=sys.stderr)
    return _serve(view)


def _serve(view) -> int:
    """Wait until Ctrl-C (SIGINT) or SIGTERM, then stop the server; exit 0."""
    import time

    def interrupt(*_):
        raise KeyboardInterrupt

    previous = signal.signal(signal.SIGTERM, interrupt)
    try:
        while True:
            time.sleep(3600)
    except KeyboardInterrupt:
        pass
    finally:
        signal.signal(signal.SIGTERM, previous)
        view.stop()
    print("rmt view: stopped", flush=True)
    return EXIT_OK


def _write_html(args, robot, world, q0, timeline, study, cell_meshes) -> int:
    """``--html OUT.html``: the scene as one self-contained page (:mod:`studies.view.html`)."""
    from studies.view.html import write_view_html
    reach = ()
    if study is not None:
        from studies.view.targets import target_colours
        colours = [f"rgb({r},{g},{b})" for r, g, b in target_colours(study)]
        reach = (("reach targets", study.positions, colours),)
    trajectory = (timeline.t, timeline.Q) if timeline is not None and timeline.timed else None
    path = timeline.Q if timeline is not None and not timeline.timed else None
    out = write_view_html(robot, world, path=path, trajectory=trajectory, reach=reach, out=args.html, q=q0,
                          cell_meshes=cell_meshes)
    print(f"rmt view: {robot.name} written to {out} (one self-contained page: open it in any browser)")
    return EXIT_OK


def add_commands(add) -> None:
    sp = add("view", cmd_view, "the robot in its cell, live in the browser: joint sliders, tool pose, σ_min, "
                               "clearance and windows read out, IK handle on the tool, path playback, reach targets "
                               "(needs the view extra: pip install 'rmtkit[view]')")
    sp.add_argument("robot", metavar="ROBOT", help="bundled name or path to a robot .toml file")
    sp.add_argument("--q", nargs="+", metavar="Q", help="the start configuration, robot file units, or a named "
                                                        "state (default: the path's first row, else home, else 0)")
    cell_args(sp)
    play = sp.add_mutually_exclusive_group()
    play.add_argument("--path", metavar="PATH.csv", help="a joint path to play (rmt plan --out: one configuration "
                                                         "per row, robot file units)")
    play.add_argument("--trajectory", metavar="TRAJ.csv", help="a timed trajectory to play in real time (rmt time "
                                                               "--out: columns t, q1 … qn in robot file units)")
    sp.add_argument("--reach", metavar="OUT_DIR", help="reach results to show as coloured targets (rmt reach --out "
                                                       "OUT_DIR, or its reach.json); a click jumps to a target's "
                                                       "configuration")
    from studies.cli.common import window_width_args
    window_width_args(sp)
    sigma_floor_args(sp, "the robot turns red where σ_min (SI) drops below S")
    sp.add_argument("--host", default="127.0.0.1", metavar="H",
                    help="the address to listen on (default 127.0.0.1: this machine only; 0.0.0.0 opens it to "
                         "the network)")
    sp.add_argument("--port", type=bounded(0, 65535, "", integer=True), default=DEFAULT_PORT, metavar="P",
                    help=f"the port (default {DEFAULT_PORT}; 0: any free port)")
    sp.add_argument("--no-browser", action="store_true", help="do not open a web browser; only print the URL")
    sp.add_argument("--html", metavar="OUT.html", help="write the scene as one self-contained HTML page (no server, "
                                                      "no network: for reports and people without Python) and exit")


__all__ = ["add_commands", "cmd_view", "DEFAULT_PORT"]
