//! The acquisition thread: the method chain runs on its own thread, because
//! an acquisition takes longer than a heartbeat period and the service
//! keeps heartbeating (the supervisor kills a service that goes silent) and
//! reading the tracker meanwhile.

use crate::chain::{Acquisition, MethodChain};
use anyhow::Context;
use spacepose_geometry::Point;
use std::sync::mpsc::{Receiver, Sender, TryRecvError, channel};
use std::thread::JoinHandle;

/// A frame to acquire on (the newest one, kept until used or replaced).
#[derive(Debug, Clone, PartialEq)]
pub struct Frame {
    /// Cloud sequence.
    pub sequence: u64,
    /// End of its scan (s).
    pub scan_end_s: f64,
    /// Its points, as received (non-finite ones included).
    pub points: Vec<Point>,
}

/// A finished acquisition.
#[derive(Debug, Clone, PartialEq)]
pub struct Done {
    /// The frame's sequence.
    pub sequence: u64,
    /// The frame's scan end (s).
    pub scan_end_s: f64,
    /// Points of the frame as received.
    pub points_in: usize,
    /// What the chain found.
    pub acquisition: Acquisition,
}

/// The thread that runs the chain, one frame at a time.
pub struct Worker {
    jobs: Sender<Frame>,
    done: Receiver<Done>,
    thread: Option<JoinHandle<()>>,
    busy: bool,
}

impl Worker {
    /// Starts the thread that owns `chain`. It ends when the worker is
    /// dropped (after the acquisition it runs, if any).
    ///
    /// # Errors
    /// The thread cannot be started.
    pub fn spawn(chain: MethodChain) -> anyhow::Result<Worker> {
        let (job_tx, job_rx) = channel::<Frame>();
        let (done_tx, done_rx) = channel::<Done>();
        let thread = std::thread::Builder::new()
            .name("acquisition".into())
            .spawn(move || {
                for job in job_rx {
                    let done = Done {
                        acquisition: chain.acquire(&job.points),
                        sequence: job.sequence,
                        scan_end_s: job.scan_end_s,
                        points_in: job.points.len(),
                    };
                    if done_tx.send(done).is_err() {
                        return;
                    }
                }
            })
            .context("starting the acquisition thread")?;
        Ok(Worker {
            jobs: job_tx,
            done: done_rx,
            thread: Some(thread),
            busy: false,
        })
    }

    /// True while an acquisition runs.
    pub fn busy(&self) -> bool {
        self.busy
    }

    /// Hands `frame` to the thread (the caller checks [`Worker::busy`]).
    ///
    /// # Panics
    /// When the thread has ended (see [`Worker::finished`]).
    pub fn start(&mut self, frame: Frame) {
        if self.jobs.send(frame).is_err() {
            self.ended();
        }
        self.busy = true;
    }

    /// The finished acquisition, if there is one.
    ///
    /// # Panics
    /// When the thread has ended: only a panic of a method ends it, and it
    /// is raised again here, so the service exits with a failure (and its
    /// supervisor restarts it) as when the thread was part of its `main`.
    pub fn finished(&mut self) -> Option<Done> {
        match self.done.try_recv() {
            Ok(done) => {
                self.busy = false;
                Some(done)
            }
            Err(TryRecvError::Empty) => None,
            Err(TryRecvError::Disconnected) => self.ended(),
        }
    }

    fn ended(&mut self) -> ! {
        tracing::error!("the acquisition thread ended");
        match self.thread.take().map(JoinHandle::join) {
            Some(Err(panic)) => std::panic::resume_unwind(panic),
            _ => panic!("the acquisition thread ended"),
        }
    }
}
