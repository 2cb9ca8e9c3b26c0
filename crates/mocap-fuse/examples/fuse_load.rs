//! Load benchmark of the fusion server: N senders at 30 Hz on loopback for
//! S seconds, each replaying a simulated sensor watching a Bandai take
//! (looped), in real time.
//!
//! ```text
//! cargo run --release -p mocap-fuse --example fuse_load -- BVH [SENDERS=8] [SECONDS=60]
//! ```

use std::time::Duration;

use mocap_fuse::{
    center_truth, runtime, send, serve, simulate, truth_from_motion, BodyModel, FusionOptions,
    JsonlSink, MeasureOptions, SendOptions, SensorFrame, SensorModel, ServeOptions,
    SimulationOptions,
};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let bvh = args
        .first()
        .ok_or("usage: fuse_load BVH [SENDERS] [SECONDS]")?;
    let senders: usize = args.get(1).map_or(Ok(8), |s| s.parse())?;
    let seconds: f64 = args.get(2).map_or(Ok(60.0), |s| s.parse())?;
    let motion = mocap_core::io::bvh::read_bvh(std::path::Path::new(bvh))?;
    let mut truth = truth_from_motion(&motion, None)?;
    center_truth(&mut truth, Some(2.0));
    let sim = simulate(
        &truth,
        &SimulationOptions {
            sensors: senders,
            model: SensorModel {
                drop_rate: (0.0, 0.0),
                ..Default::default()
            },
            ..Default::default()
        },
    );
    let body = BodyModel::measure(
        sim.sensors
            .iter()
            .flat_map(|s| s.frames.iter().map(|f| &f.joints)),
        MeasureOptions::default(),
    );
    // Loop each sensor's frames to cover the duration, on a fresh clock.
    let period = 1.0 / 30.0;
    let streams: Vec<Vec<SensorFrame>> = sim
        .sensors
        .iter()
        .map(|s| {
            let n = (seconds * 30.0) as usize;
            (0..n)
                .map(|i| {
                    let mut f = s.frames[i % s.frames.len()].clone();
                    f.seq = i as u64;
                    let phase = s.frames[0].timestamp;
                    f.timestamp = phase + i as f64 * period;
                    f.arrival = Some(f.timestamp);
                    f
                })
                .collect()
        })
        .collect();
    let out = std::env::temp_dir().join("fuse_load.jsonl");
    let rt = runtime()?;
    let report = rt.block_on(async {
        let (tx, rx) = tokio::sync::oneshot::channel();
        let mut sink = JsonlSink::create(out.clone())?;
        let options = ServeOptions {
            listen: "127.0.0.1:0".parse().unwrap(),
            calibration: sim.calibration(),
            body,
            fusion: FusionOptions::best(),
            fps: 30.0,
            wait: 0.1,
            sensor_timeout: 0.5,
            max_skew: mocap_fuse::DEFAULT_MAX_SKEW,
            duration: Some(Duration::from_secs_f64(seconds + 1.5)),
            idle_exit: None,
        };
        let server = serve(options, &mut sink, std::future::pending(), Some(tx));
        let clients = async {
            let addr = rx.await.unwrap();
            let tasks: Vec<_> = streams
                .iter()
                .map(|s| {
                    send(
                        s,
                        SendOptions {
                            to: addr,
                            realtime: true,
                            speed: 1.0,
                        },
                    )
                })
                .collect();
            futures_join_all(tasks).await
        };
        let (report, sent) = tokio::join!(server, clients);
        let sent: u64 = sent
            .into_iter()
            .map(|r| r.map(|r| r.datagrams).unwrap_or(0))
            .sum();
        report.map(|r| (r, sent))
    })?;
    let (report, sent) = report;
    println!("senders {senders}, seconds {seconds}, datagrams sent {sent}");
    println!("{}", serde_json::to_string_pretty(&report)?);
    println!(
        "fusion throughput: {:.0} sensor-joint observations per second of fusion time",
        report.observations as f64 / report.fusion_seconds.max(1e-9)
    );
    Ok(())
}

/// Awaits all futures concurrently on the current task (no extra crate).
async fn futures_join_all<F: std::future::Future>(futures: Vec<F>) -> Vec<F::Output> {
    let mut out = Vec::new();
    let mut pending: Vec<Option<std::pin::Pin<Box<F>>>> =
        futures.into_iter().map(|f| Some(Box::pin(f))).collect();
    let mut results: Vec<Option<F::Output>> = (0..pending.len()).map(|_| None).collect();
    std::future::poll_fn(|cx| {
        let mut all = true;
        for (i, slot) in pending.iter_mut().enumerate() {
            if let Some(f) = slot {
                match f.as_mut().poll(cx) {
                    std::task::Poll::Ready(v) => {
                        results[i] = Some(v);
                        *slot = None;
                    }
                    std::task::Poll::Pending => all = false,
                }
            }
        }
        if all {
            std::task::Poll::Ready(())
        } else {
            std::task::Poll::Pending
        }
    })
    .await;
    for r in results {
        out.push(r.unwrap());
    }
    out
}
