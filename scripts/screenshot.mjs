// Opens the Rerun web viewer URL given as argv[2] in headless Debian Chromium (software WebGL),
// waits for the viewer to start and draw the live fleet, and saves a screenshot to argv[3].
// Run by scripts/screenshot.sh, which installs playwright-core.
import { chromium } from "playwright-core";

const [url, out, waitMs = "30000"] = process.argv.slice(2);
const browser = await chromium.launch({
  executablePath: "/usr/bin/chromium",
  args: [
    "--no-sandbox", "--disable-gpu-sandbox", "--no-first-run", "--disable-background-networking",
    "--disable-component-update", "--disable-sync", "--disable-quic",
    "--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--ignore-gpu-blocklist",
  ],
});
const page = await browser.newPage({ viewport: { width: 1600, height: 900 } });
page.on("console", (m) => { if (m.type() === "error") console.error("page:", m.text()); });
await page.goto(url);
await page.waitForTimeout(Number(waitMs));
// Software WebGL on a busy 2-core machine can take a while to hand over a frame.
await page.screenshot({ path: out, timeout: 600000 });
await browser.close();
console.log(`saved ${out}`);
