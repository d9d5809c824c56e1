"""A screenshot of a page in headless Chromium after it has rendered for a while, through the
DevTools protocol (Chromium's own --screenshot fires before the Rerun web viewer has loaded).

    pip install websocket-client==1.8.0        # and Debian's chromium
    rerun --serve-web --web-viewer-port 9095 --port 9877 RECORDING.rrd &
    python results/screenshot.py \
        "http://127.0.0.1:9095?url=rerun%2Bhttp%3A%2F%2Flocalhost%3A9877%2Fproxy" OUT.png 45

The last argument is how many seconds the page renders before the shot.
"""
import json, subprocess, sys, time, urllib.request, base64
import websocket

url, out, wait = sys.argv[1], sys.argv[2], float(sys.argv[3])
port = 9333
chrome = subprocess.Popen([
    "chromium", "--headless=new", "--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
    "--window-size=1600,1000", f"--remote-debugging-port={port}", "--remote-allow-origins=*", "about:blank"],
    stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
try:
    for _ in range(50):
        try:
            tabs = json.load(urllib.request.urlopen(f"http://127.0.0.1:{port}/json"))
            break
        except Exception:
            time.sleep(0.2)
    tab = [t for t in tabs if t["type"] == "page"][0]
    ws = websocket.create_connection(tab["webSocketDebuggerUrl"], timeout=60)
    n = 0
    def call(method, **params):
        global n
        n += 1
        ws.send(json.dumps({"id": n, "method": method, "params": params}))
        while True:
            msg = json.loads(ws.recv())
            if msg.get("id") == n:
                return msg.get("result", {})
    call("Page.enable")
    call("Page.navigate", url=url)
    time.sleep(wait)
    shot = call("Page.captureScreenshot", format="png")
    open(out, "wb").write(base64.b64decode(shot["data"]))
    print("written", out)
finally:
    chrome.kill()
