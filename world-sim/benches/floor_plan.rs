//! Floor plans (issue 47): loading a Nav2 map of 1,000 × 1,700 pixels (50 × 85 m at 5 cm)
//! and building its site (walls, clearance, routing grid, a cost-to-go field per station),
//! target ≤ 1 s, and the same with a keep-out mask (the robots' and the people's routers),
//! target ≤ 1 s; and one route between stations on it, which every task and every person's
//! new goal asks for.
//!
//!     cargo bench -p world-sim --bench floor_plan
//!
//! The map is drawn here: a perimeter wall, 10 rows of racks in 4 blocks, unknown space
//! round the building and scanner noise (1 in 500 free pixels grey), written as a PNG.

use agent::math::{Vec2, vec2};
use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use world_sim::floor_plan::FloorPlan;
use world_sim::floor_plan::nav2::{Cell, MapYaml, OccupancyGrid};
use world_sim::floor_plan::router::Router;

const W: usize = 1000;
const H: usize = 1700;

/// The map's PNG and its stations (10 docks along the bottom, 40 picks at rack faces).
fn warehouse_png() -> (Vec<u8>, Vec<Vec2>) {
    let mut px = vec![255_u8; W * H];
    let mut seed = 7_u64;
    for (i, p) in px.iter_mut().enumerate() {
        let (x, row) = (i % W, i / W);
        let y = H - 1 - row;
        let outside = x < 20 || y < 20 || x >= W - 20 || y >= H - 20;
        let wall = x < 24 || y < 24 || x >= W - 24 || y >= H - 24;
        // Racks: 10 rows 1.2 m deep (24 px) every 6 m (120 px) from y = 10 m, in 4 blocks
        // 9 m long (180 px) with 3 m cross-aisles.
        let (ry, rx) = ((y as isize - 200) % 120, (x as isize - 60) % 240);
        let rack = (200..200 + 10 * 120).contains(&y)
            && ry < 24
            && (60..60 + 4 * 240).contains(&x)
            && rx < 180;
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        *p = if outside {
            205
        } else if wall || rack {
            0
        } else if seed >> 55 == 0 {
            205
        } else {
            254
        };
    }
    let mut png = Vec::new();
    let mut enc = png::Encoder::new(&mut png, W as u32, H as u32);
    enc.set_color(png::ColorType::Grayscale);
    enc.set_depth(png::BitDepth::Eight);
    enc.write_header()
        .and_then(|mut w| w.write_image_data(&px))
        .expect("an in-memory PNG");
    let mut stations: Vec<Vec2> = (0..10).map(|k| vec2(3.0 + 4.5 * k as f64, 3.0)).collect();
    for r in 0..10 {
        for b in 0..4 {
            stations.push(vec2(
                3.0 + 12.0 * b as f64 + 4.5,
                10.0 + 6.0 * r as f64 + 2.5,
            ));
        }
    }
    (png, stations)
}

/// A keep-out mask over the map at 0.1 m: free, with a 3 × 2 m zone in the cross-aisle after
/// each of the first three blocks, between the second and third rack rows.
fn keepout_mask() -> OccupancyGrid {
    let (w, h) = (W / 2, H / 2);
    let mut cells = vec![Cell::Free; w * h];
    for b in 0..3 {
        let x0 = 60 + b * 120 + 90; // the block's end (0.1 m cells)
        for y in 175..195 {
            for x in x0..x0 + 30 {
                cells[y * w + x] = Cell::Occupied;
            }
        }
    }
    OccupancyGrid {
        width: w,
        height: h,
        resolution: 0.1,
        origin: vec2(0.0, 0.0),
        cells,
    }
}

fn floor_plan(c: &mut Criterion) {
    let (png, stations) = warehouse_png();
    let yaml = "image: map.png\nresolution: 0.05\norigin: [0.0, 0.0, 0.0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n";
    let mut group = c.benchmark_group("floor_plan");
    group.sample_size(10);
    group.bench_function("load_and_build/1000x1700", |b| {
        b.iter(|| {
            let meta = MapYaml::parse(yaml, "map.yaml").expect("valid");
            let grid = meta.grid(&png, "map.png").expect("decodes");
            let plan = FloorPlan::from_grid("bench".to_owned(), grid, 0);
            black_box(Router::new(&plan.grid, &plan.floor, 0.3, &stations))
        });
    });
    // The same with a keep-out mask at 0.1 m (500 × 850 cells) closing a 3 × 2 m packing area
    // in each block's cross-aisle: the robots' walls and router, and the people's router.
    let mask = keepout_mask();
    group.bench_function("load_and_build_with_keepout/1000x1700", |b| {
        b.iter(|| {
            let meta = MapYaml::parse(yaml, "map.yaml").expect("valid");
            let grid = meta.grid(&png, "map.png").expect("decodes");
            let plan = FloorPlan::from_grid("bench".to_owned(), grid, 0).with_keepout(
                &mask,
                1,
                "mask.yaml",
            );
            black_box((
                plan.router(0.3, &stations),
                plan.people_router(0.3, &stations),
            ))
        });
    });
    let meta = MapYaml::parse(yaml, "map.yaml").expect("valid");
    let plan = FloorPlan::from_grid(
        "bench".to_owned(),
        meta.grid(&png, "map.png").expect("decodes"),
        0,
    );
    eprintln!("{} walls", plan.obstacles.len());
    let router = Router::new(&plan.grid, &plan.floor, 0.3, &stations);
    let (from, to) = (stations[0], stations[stations.len() - 1]);
    assert!(router.route(from, to).len() > 1, "a route round the racks");
    group.bench_function("route_to_a_station/1000x1700", |b| {
        b.iter(|| black_box(router.route(black_box(from), black_box(to))));
    });
    group.finish();
}

criterion_group!(benches, floor_plan);
criterion_main!(benches);
