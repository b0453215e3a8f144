//! End-to-end test of `rh-score --html`: a small rendered build (quick-start-like: the
//! quick start's five baselines, three families, every scene rendered at a small size) is
//! scored into a static site, which real headless Chromium (Debian's `chromium`, from
//! scripts/setup.sh) opens from file:// over the DevTools pipe: no console errors, one
//! leaderboard row per model, sortable, a filter changes the number of listed scenes, a
//! scene page's videos decode (readyState ≥ 2) and play in sync, and the planned-hands
//! overlay is drawn; at 800 and 1400 px no page scrolls sideways and the counts of the
//! board, its rows and the scene list agree. The screenshots in the README come from this
//! test (`RH_UPDATE_SCREENSHOTS=1` writes them to docs/screenshots/).

use rh_e2e::cdp::{chromium_path, Browser};
use rh_e2e::run_ok;
use std::path::{Path, PathBuf};
use std::time::Duration;

const W: u32 = 320;
const H: u32 = 180;
const FAMILIES: &str = "object_drop,sliding_object,thrown_object";
const BASELINES: [&str; 5] = ["oracle", "majority", "random", "always-catch", "freeze"];

fn small_config(dir: &Path) -> PathBuf {
    rh_e2e::small_render_config(dir, W, H, false)
}

fn url(site: &Path, page: &str) -> String {
    format!("file://{}/{page}", site.canonicalize().unwrap().display())
}

fn count(b: &mut Browser) -> u64 {
    b.eval("+document.getElementById('count').dataset.count")
        .as_u64()
        .expect("count")
}

#[test]
fn html_site_opens_in_headless_chromium() {
    let chromium = chromium_path().expect("chromium is installed by scripts/setup.sh");
    let tmp = tempfile::tempdir().unwrap();
    let config = small_config(tmp.path());
    let dataset = tmp.path().join("dataset");
    run_ok(
        "rh-pipeline",
        &[
            "--config",
            config.to_str().unwrap(),
            "build",
            "--n",
            "12",
            "--seed",
            "0",
            "--quiet",
            "--families",
            FAMILIES,
            "--out",
            dataset.to_str().unwrap(),
        ],
    );
    let ds = dataset.to_str().unwrap();
    // The scenes rh-score scores and the site lists: the evaluation subset (label rule v5
    // keeps at most one NO_ACTION per family there).
    let scored = eval_rows(&dataset);
    assert!(scored >= 4, "{scored} scenes in the eval subset");
    let mut preds = String::new();
    for b in BASELINES {
        preds += &run_ok("rh-score", &["baseline", b, "--dataset", ds, "--model", b]);
    }
    let preds_file = tmp.path().join("preds.jsonl");
    std::fs::write(&preds_file, preds).unwrap();
    let site = tmp.path().join("site");
    let out = rh_e2e::run(
        "rh-score",
        &[
            preds_file.to_str().unwrap(),
            "--dataset",
            ds,
            "--quiet",
            "--html",
            site.to_str().unwrap(),
        ],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("index.html"),
        "says where to open it: {stderr}"
    );
    for f in [
        "index.html",
        "scenes.html",
        "scene.html",
        "data/index.js",
        "assets/site.js",
    ] {
        assert!(site.join(f).is_file(), "{f}");
    }
    // Self-contained: nothing is fetched from another origin.
    for f in ["index.html", "scenes.html", "scene.html", "assets/site.js"] {
        let text = std::fs::read_to_string(site.join(f)).unwrap();
        for pat in ["src=\"http", "href=\"http", "url(http", "import "] {
            assert!(
                !text.contains(pat),
                "{f} loads something from the network: {pat}"
            );
        }
    }

    let profile = tmp.path().join("chromium-profile");
    let mut b = Browser::launch(&chromium, &profile, 1200, 800);

    // Leaderboard: one row per model, sortable.
    b.goto(&url(&site, "index.html"));
    let rows = b.eval("document.querySelectorAll('#leaderboard tbody tr').length");
    assert_eq!(rows.as_u64(), Some(BASELINES.len() as u64));
    let figures = b.eval("document.querySelectorAll('.figures svg').length");
    assert_eq!(figures.as_u64(), Some(4), "the four figures inline as SVG");
    let first = b.eval(
        "document.querySelector('#leaderboard th[data-col=model]').click(); \
         document.querySelector('#leaderboard tbody tr').dataset.model",
    );
    let mut sorted = BASELINES.to_vec();
    sorted.sort();
    assert_eq!(first.as_str(), Some(sorted[0]), "sorting by model name");
    let shot_board = b.screenshot();

    // Scene browser: a filter changes the number of listed scenes.
    b.goto(&url(&site, "scenes.html"));
    let all = count(&mut b);
    assert_eq!(all, scored, "every scored scene is listed");
    let listed = b.eval("document.querySelectorAll('#scene-list tbody tr').length");
    assert_eq!(listed.as_u64(), Some(scored));
    // The first family (in the filter's order) that lists some but not all scenes.
    b.eval(&format!(
        "(() => {{ const s = document.getElementById('f-family'); \
         for (const o of s.options) {{ if (!o.value) continue; s.value = o.value; \
         s.dispatchEvent(new Event('change', {{bubbles: true}})); \
         const n = +document.getElementById('count').dataset.count; \
         if (n > 0 && n < {all}) return n; }} return 0; }})()"
    ));
    let family = count(&mut b);
    assert!(
        family > 0 && family < all,
        "family filter: {family} of {all}"
    );
    let model_rule = b.eval(
        "(() => { const f = document.getElementById('f-family'); f.value = ''; \
         const m = document.getElementById('f-model'); m.value = 'oracle'; \
         const r = document.getElementById('f-rule'); r.value = 'unsafe'; \
         r.dispatchEvent(new Event('change', {bubbles: true})); \
         return +document.getElementById('count').dataset.count; })()",
    );
    assert_eq!(
        model_rule.as_u64(),
        Some(0),
        "the oracle never fires a safety rule"
    );
    // A CATCH scene for the scene page (the oracle reaches for it), else the first one.
    let scene = b.eval(
        "(() => { const r = document.getElementById('f-rule'); r.value = ''; \
         const m = document.getElementById('f-model'); m.value = ''; \
         const g = document.getElementById('f-gt'); g.value = 'CATCH'; \
         g.dispatchEvent(new Event('change', {bubbles: true})); \
         let a = document.querySelector('#scene-list tbody a'); \
         if (!a) { g.value = ''; g.dispatchEvent(new Event('change', {bubbles: true})); \
                   a = document.querySelector('#scene-list tbody a'); } \
         return a.getAttribute('href'); })()",
    );
    let scene = scene.as_str().expect("a scene link").to_string();

    // Scene page: videos decode and play in sync; the overlay is drawn.
    b.goto(&url(&site, &scene));
    let states = b.eval(
        "new Promise(done => { const t0 = Date.now(); (function poll() { \
           const v = [...document.querySelectorAll('video')]; \
           if ((v.length && v.every(x => x.readyState >= 2)) || Date.now() - t0 > 30000) \
             done(v.map(x => [x.dataset.cam, x.readyState, x.error ? x.error.code : 0])); \
           else setTimeout(poll, 100); })(); })",
    );
    let states = states.as_array().expect("video states").clone();
    assert_eq!(
        states.len(),
        4,
        "three observation videos and the full event: {states:?}"
    );
    for s in &states {
        assert!(
            s[1].as_u64().unwrap() >= 2,
            "video not decodable: {states:?}"
        );
    }
    let paths = b.eval("+document.getElementById('overlay').dataset.paths");
    assert_eq!(
        paths.as_u64(),
        Some(BASELINES.len() as u64),
        "one hand path per model"
    );
    // Pixels of the overlay on the canvas: the models' colours (the site's palette), the
    // hazard's path (white) and its current position (yellow). Since label rule v2 the
    // observer often stands beyond the overhead view's frame (it is framed on the hazard's
    // observation-window path), so the planned hands may lie off-image; the hazard's path
    // never does.
    let coloured = b.eval(
        "(() => { const c = document.getElementById('overlay'); \
         const pal = [[31,119,180],[255,127,14],[44,160,44],[214,39,40],[148,103,189],[255,255,255],[255,212,0]]; \
         const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data; let n = 0; \
         for (let i = 0; i < d.length; i += 4) \
           if (d[i+3] > 200 && pal.some(p => Math.abs(d[i]-p[0]) < 20 && Math.abs(d[i+1]-p[1]) < 20 && Math.abs(d[i+2]-p[2]) < 20)) n++; \
         return n; })()",
    );
    assert!(
        coloured.as_u64().unwrap() >= 10,
        "the overlay is drawn: {coloured}"
    );
    let decisions = b.eval("document.querySelectorAll('#decisions tbody tr').length");
    assert_eq!(decisions.as_u64(), Some(BASELINES.len() as u64));
    // Screenshot mid-window (paused), then play.
    b.eval(
        "(() => { const s = document.getElementById('scrub'); s.value = '500'; \
         s.dispatchEvent(new Event('input')); \
         return new Promise(d => setTimeout(d, 500)); })()",
    );
    let shot_scene = b.screenshot();
    b.eval(
        "(() => { const s = document.getElementById('scrub'); s.value = '0'; \
         s.dispatchEvent(new Event('input')); \
         return new Promise(d => setTimeout(d, 300)); })()",
    );
    b.eval("document.getElementById('play').click()");
    b.pause(Duration::from_millis(300));
    let times = b.eval("[...document.querySelectorAll('.cams video')].map(v => v.currentTime)");
    let times: Vec<f64> = times
        .as_array()
        .unwrap()
        .iter()
        .map(|t| t.as_f64().unwrap())
        .collect();
    assert_eq!(times.len(), 3);
    let (lo, hi) = times
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), &t| (a.min(t), b.max(t)));
    assert!(
        lo > 0.05 && hi - lo < 0.1,
        "videos play (from 0) in sync: {times:?}"
    );

    assert!(b.errors.is_empty(), "console errors: {:#?}", b.errors);

    // Predictions that carry a prompt version show it on the leaderboard; rewriting a
    // site replaces it, and a directory that is not a site is refused (exit 2).
    let tagged: String = std::fs::read_to_string(&preds_file)
        .unwrap()
        .lines()
        .map(|l| {
            let mut v: serde_json::Value = serde_json::from_str(l).unwrap();
            if v["model"] == "oracle" {
                v["prompt_version"] = serde_json::json!("rh-prompt-test-7");
            }
            v.to_string() + "\n"
        })
        .collect();
    std::fs::write(&preds_file, tagged).unwrap();
    run_ok(
        "rh-score",
        &[
            preds_file.to_str().unwrap(),
            "--dataset",
            ds,
            "--quiet",
            "--html",
            site.to_str().unwrap(),
        ],
    );
    let index = std::fs::read_to_string(site.join("index.html")).unwrap();
    assert!(
        index.contains("\"prompt_versions\":[\"rh-prompt-test-7\"]"),
        "prompt version on the board"
    );
    let scene_js = std::fs::read_to_string(site.join(format!(
        "data/{}",
        scene.replace("scene.html#", "scenes/") + ".js"
    )))
    .unwrap();
    assert!(
        scene_js.contains("rh-prompt-test-7"),
        "prompt version on the scene page"
    );
    let refused = rh_e2e::run(
        "rh-score",
        &[
            preds_file.to_str().unwrap(),
            "--dataset",
            ds,
            "--quiet",
            "--html",
            dataset.to_str().unwrap(),
        ],
    );
    assert_eq!(
        refused.status.code(),
        Some(2),
        "a non-site directory is not replaced"
    );
    assert!(dataset.join("README.md").exists());

    // The scene list's colours have a legend: colour says correct, ⚠ says unsafe.
    b.goto(&url(&site, "scenes.html"));
    let legend = b.eval("document.getElementById('legend').textContent");
    let legend = legend.as_str().unwrap_or_default();
    assert!(
        legend.contains("correct (derived action = GT)") && legend.contains("a safety rule fired"),
        "{legend}"
    );
    // The leaderboard shows coverage and 95% intervals.
    b.goto(&url(&site, "index.html"));
    let cells = b.eval(
        "[...document.querySelectorAll('#leaderboard tbody tr:first-child td')].map(td => td.textContent).join('|')",
    );
    let cells = cells.as_str().unwrap_or_default();
    assert!(
        cells.contains(&format!("{scored}/{scored}")) && cells.contains("–"),
        "{cells}"
    );

    // With --execute the leaderboard gains the outcome columns and still fits 1400 px.
    let exec_site = tmp.path().join("site-exec");
    run_ok(
        "rh-score",
        &[
            preds_file.to_str().unwrap(),
            "--dataset",
            ds,
            "--quiet",
            "--execute",
            "--no-exec-cache",
            "--html",
            exec_site.to_str().unwrap(),
        ],
    );
    let mut wide = Browser::launch(&chromium, &tmp.path().join("chromium-1400"), 1400, 900);
    wide.goto(&url(&exec_site, "index.html"));
    let struck = wide.eval(
        "[...document.querySelectorAll('#leaderboard th')].filter(th => th.textContent.startsWith('struck')).length",
    );
    assert_eq!(struck.as_u64(), Some(1), "a struck % column");
    let right = wide
        .eval("document.getElementById('leaderboard').getBoundingClientRect().right")
        .as_f64()
        .unwrap();
    let shot_exec = wide.screenshot();
    assert!(right <= 1400.0, "the leaderboard ends at {right} px");
    assert!(wide.errors.is_empty(), "console errors: {:#?}", wide.errors);

    let shots = Path::new(env!("CARGO_TARGET_TMPDIR")).join("screenshots");
    std::fs::create_dir_all(&shots).unwrap();
    // At 800 and 1400 px: no page scrolls sideways and every count agrees.
    for width in [800, 1400] {
        let profile = tmp.path().join(format!("chromium-layout-{width}"));
        let mut b = Browser::launch(&chromium, &profile, width, 2000);
        layout_checks(&mut b, &site, width, scored, &scene, &shots);
        assert!(
            b.errors.is_empty(),
            "{width} px: console errors: {:#?}",
            b.errors
        );
    }
    std::fs::write(shots.join("leaderboard.png"), &shot_board).unwrap();
    std::fs::write(shots.join("scene.png"), &shot_scene).unwrap();
    std::fs::write(shots.join("leaderboard-execute-1400.png"), &shot_exec).unwrap();
    assert_eq!(&shot_board[1..4], b"PNG");
    if std::env::var_os("RH_UPDATE_SCREENSHOTS").is_some() {
        let docs = Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/screenshots");
        std::fs::create_dir_all(&docs).unwrap();
        std::fs::write(docs.join("leaderboard.png"), &shot_board).unwrap();
        std::fs::write(docs.join("scene.png"), &shot_scene).unwrap();
    }
}

/// The pages at `width` px: nothing wider than the window, the counts of the board's note,
/// its rows and the scene list the same (`scored`), the scene list's object names and
/// thumbnails, the scene page's clock before Play and its previous / next links, and
/// every header's definition link pointing at a definition. Screenshots go to `shots`.
fn layout_checks(b: &mut Browser, site: &Path, width: u32, scored: u64, scene: &str, shots: &Path) {
    let overflow = "[document.documentElement.scrollWidth, window.innerWidth]";
    let fits = |b: &mut Browser, page: &str| {
        let v = b.eval(overflow);
        let (sw, iw) = (v[0].as_u64().unwrap(), v[1].as_u64().unwrap());
        assert!(
            sw <= iw,
            "{page} at {width} px scrolls sideways: {sw} > {iw}"
        );
    };
    b.goto(&url(site, "index.html"));
    fits(b, "index.html");
    let expected = b.eval("+document.getElementById('board-note').dataset.expected");
    assert_eq!(
        expected.as_u64(),
        Some(scored),
        "the board's note counts the scored scenes"
    );
    let note = b.eval("document.getElementById('board-note').textContent");
    let note = note.as_str().unwrap_or_default().to_string();
    assert!(note.contains(&format!("on {scored} scenes")), "{note}");
    let answered = b.eval(
        "[...document.querySelectorAll('#leaderboard tbody tr')].map(tr => tr.children[1].textContent.split('/')[1])",
    );
    for a in answered.as_array().unwrap() {
        let n: u64 = a
            .as_str()
            .unwrap()
            .trim_end_matches("incomplete")
            .parse()
            .unwrap();
        assert_eq!(n, scored, "a row's expected scenes");
    }
    let defs = b.eval(
        "[...document.querySelectorAll('#leaderboard a.def')].map(a => a.getAttribute('href')) \
         .filter(h => !document.getElementById(h.slice(1)))",
    );
    assert_eq!(
        defs.as_array().map(Vec::len),
        Some(0),
        "dangling definitions: {defs}"
    );
    let n_defs = b.eval("document.querySelectorAll('#leaderboard a.def').length");
    assert!(
        n_defs.as_u64().unwrap() >= 6,
        "definition links in the headers"
    );
    let captions = b.eval("[...document.querySelectorAll('.figures figcaption .caption')].filter(c => c.textContent.length > 100).length");
    assert_eq!(captions.as_u64(), Some(4), "every figure has its caption");
    std::fs::write(shots.join(format!("board-{width}.png")), b.screenshot()).unwrap();

    b.goto(&url(site, "scenes.html"));
    fits(b, "scenes.html");
    let total = b.eval("+document.getElementById('count').dataset.total");
    assert_eq!(
        total.as_u64(),
        Some(scored),
        "the scene list counts the scored scenes"
    );
    let listed = b.eval(
        "[...document.querySelectorAll('#scene-list tbody tr')].map(tr => [tr.querySelector('small.sub') ? tr.querySelector('small.sub').textContent : '', \
           !!tr.querySelector('td.thumb img')])",
    );
    for row in listed.as_array().unwrap() {
        assert!(
            !row[0].as_str().unwrap().is_empty(),
            "an object name per scene: {listed}"
        );
        assert!(
            row[1].as_bool().unwrap(),
            "a thumbnail per scene (frames exist): {listed}"
        );
    }
    let cells = b.eval("[document.querySelectorAll('td.dec.correct').length, document.querySelectorAll('td.dec.wrong').length]");
    assert!(
        cells[0].as_u64().unwrap() > 0 && cells[1].as_u64().unwrap() > 0,
        "correct and wrong cells: {cells}"
    );
    let thumbs_shown = b.eval(
        "[...document.querySelectorAll('td.thumb img')].filter(i => i.offsetWidth > 0).length",
    );
    if width >= 1400 {
        assert!(
            thumbs_shown.as_u64().unwrap() > 0,
            "thumbnails shown at {width} px"
        );
    }
    std::fs::write(shots.join(format!("scenes-{width}.png")), b.screenshot()).unwrap();

    b.goto(&url(site, scene));
    fits(b, scene);
    let clock = b.eval("document.getElementById('clock').textContent");
    assert!(
        clock
            .as_str()
            .unwrap_or_default()
            .starts_with("t = 0.000 s"),
        "clock before Play: {clock}"
    );
    let links = b.eval(
        "[!!document.getElementById('prev-scene') || !!document.querySelector('#prevnext .off'), \
        !!document.getElementById('next-scene') || !!document.querySelector('#prevnext .off')]",
    );
    assert_eq!(links, serde_json::json!([true, true]), "previous / next");
    let some_link = b.eval("document.querySelectorAll('#prev-scene, #next-scene').length");
    assert!(
        some_link.as_u64().unwrap() >= 1,
        "a neighbour scene is linked"
    );
    std::fs::write(shots.join(format!("scene-{width}.png")), b.screenshot()).unwrap();
}

/// Rows of a dataset's `eval` config (pyarrow reads the Parquet footer).
fn eval_rows(dataset: &std::path::Path) -> u64 {
    let out = std::process::Command::new("python3")
        .arg("-c")
        .arg(format!(
            "import glob, pyarrow.parquet as pq; print(sum(pq.read_metadata(f).num_rows for f in glob.glob({:?} + '/eval/*.parquet')))",
            dataset.display().to_string()
        ))
        .output()
        .expect("python3 with pyarrow (scripts/setup.sh)");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).trim().parse().unwrap()
}
