"""``animate``: crack-growth animation of a creep run folder (GIF, and MP4 where ffmpeg exists)."""
from __future__ import annotations


def register(sub, common):
    from ..analysis.animation import DEFAULT_FPS, DEFAULT_FRAMES
    p = sub.add_parser("animate", help="crack-growth animation of a creep run (GIF; MP4 where ffmpeg exists)")
    p.add_argument("run_dir", metavar="RUN_DIR", help="folder of a creep run (its cracks.csv, history.csv, params.json)")
    p.add_argument("--log-time", action="store_true",
                   help="frames spaced logarithmically in creep time (the last three decades of the run)")
    p.add_argument("--fps", type=float, default=DEFAULT_FPS, help=f"frames per second (default {DEFAULT_FPS})")
    p.add_argument("--frames", type=int, default=DEFAULT_FRAMES, help=f"number of frames (default {DEFAULT_FRAMES})")
    p.add_argument("--no-mp4", action="store_true", help="write the GIF only, even where ffmpeg exists")
    p.set_defaults(func=cmd_animate)


def cmd_animate(args) -> int:
    from ..analysis.animation import animate_run
    out = animate_run(args.run_dir, log_time=args.log_time, fps=args.fps, frames=args.frames, mp4=not args.no_mp4)
    mp4 = out["mp4"] or ("not written (--no-mp4)" if args.no_mp4 else "not written (no ffmpeg)")
    print(f"{out['frames']} frames: {out['gif']}, MP4 {mp4}, last frame {out['frame_png']} ({out['grains']})")
    return 0
