"""SVG panels stacked over one frame axis, for the long-run figures (bench/soak_report.py,
bench/long_run_report.py): each panel is a box from 0 to its y_max with its label on the left."""
import html


class FramePanels:
    def __init__(self, width, left, right, panel_height, x_max):
        self.width, self.left, self.right = width, left, right
        self.panel_height, self.x_max = panel_height, max(x_max, 1)

    def x(self, frame):
        """The x pixel of a frame."""
        return self.left + (self.width - self.left - self.right) * frame / self.x_max

    def line(self, points, y_max, top, colour, width=1.5):
        """A polyline of (frame, value) in the panel at `top`; values above y_max are clipped."""
        ph = self.panel_height
        pts = " ".join(f"{self.x(f):.1f},{top + ph - ph * min(v, y_max) / max(y_max, 1e-9):.1f}"
                       for f, v in points)
        return f'<polyline fill="none" stroke="{colour}" stroke-width="{width}" points="{pts}"/>'

    def axes(self, top, y_max, label, colour):
        """The panel's box, its 0 and y_max ticks and its label."""
        l, ph = self.left, self.panel_height
        return [f'<rect x="{l}" y="{top}" width="{self.width - l - self.right}" height="{ph}" '
                f'fill="none" stroke="#999"/>',
                f'<text x="{l - 8}" y="{top + 4}" text-anchor="end" font-size="11">{y_max:.0f}</text>',
                f'<text x="{l - 8}" y="{top + ph}" text-anchor="end" font-size="11">0</text>',
                f'<text x="{l - 8}" y="{top + ph / 2}" text-anchor="end" font-size="11" '
                f'fill="{colour}">{html.escape(label)}</text>']
