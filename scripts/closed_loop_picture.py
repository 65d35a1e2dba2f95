import sys
sys.path.insert(0, "src")
from pathlib import Path
import legkin
from legkin.viewer import open_viewer, screenshot
from PIL import Image
D = "/work/shared/data/example-parallel-robots/"
imgs = []
for name, cam in [("cassie_like", (1.0, -0.5, 0.9)), ("digit_like", (0.6, -0.2, 0.75))]:
    r = legkin.load(D + name + "/robot.urdf")
    with open_viewer(r, camera=cam, ground=False) as viz:
        viz.display(r.q0)
        viz.viewer["/Grid"].set_property("visible", False)
        viz.viewer["/Axes"].set_property("visible", False)
        html = viz.viewer.static_html()
    Path(f"/tmp/closed/{name}.html").write_text(html)
    screenshot(f"/tmp/closed/{name}.html", f"/tmp/closed/{name}.png", size=(420, 520))
    imgs.append(Image.open(f"/tmp/closed/{name}.png").convert("RGB").crop((0, 20, 420, 520)))
out = Image.new("RGB", (840, 500), "white")
out.paste(imgs[0], (0, 0)); out.paste(imgs[1], (420, 0))
out.save("docs/img/closed_loop_files.png", optimize=True)
