//! The `.rrd` file: rerun's own chunk builder and encoder, with rows batched per entity.
//!
//! Why not rerun's `RecordingStream`: it lives in `re_sdk`, whose `re_lenses -> re_mcap`
//! dependency turns on `re_sdk_types/glam` (glam 0.30) in every feature set, and DESIGN.md
//! allows one glam. Its archetypes, chunks and encoder are the crates below it, used here
//! directly. That also keeps the file free of wall-clock timelines (the stream adds `log_time`
//! and `log_tick` to every row), writes synchronously (an I/O error comes back to the run
//! instead of dying in a sink thread), and needs no threads.

use re_chunk::{Chunk, ChunkBuilder, EntityPath, RowId, TimePoint};
use re_log_encoding::{CrateVersion, Encoder, EncodingOptions};
use re_log_types::{LogMsg, SetStoreInfo, StoreId, StoreInfo, StoreKind, StoreSource, TimeCell};
use re_sdk_types::AsComponents;
use re_sdk_types::archetypes::RecordingInfo;
use std::collections::BTreeMap;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

/// The one timeline of a recording: simulated time since the start of the run.
pub const SIM_TIME: &str = "sim_time";

/// Rows of one entity kept before they are written as one chunk. Fewer, larger chunks make a
/// smaller file (each chunk carries its own Arrow schema) and a faster viewer.
const ROWS_PER_CHUNK: usize = 64;

/// The recording file being written.
pub struct RrdWriter {
    encoder: Encoder<BufWriter<File>>,
    store: StoreId,
    /// Rows not yet written, per entity (ordered, so the file's chunk order is a function of
    /// what was logged).
    pending: BTreeMap<EntityPath, PendingChunk>,
    /// The first failure; once set, nothing more is written and `finish` reports it.
    error: Option<String>,
    path: PathBuf,
}

struct PendingChunk {
    builder: ChunkBuilder,
    rows: usize,
}

impl RrdWriter {
    /// Creates `path` and writes the recording's header: store `uavex`, named `name`.
    pub fn create(path: &Path, name: &str) -> Result<Self, String> {
        let describe = |e: &dyn std::fmt::Display| format!("{}: {e}", path.display());
        let file = File::create(path).map_err(|e| describe(&e))?;
        let mut encoder = Encoder::new_eager(
            CrateVersion::LOCAL,
            EncodingOptions::PROTOBUF_COMPRESSED,
            BufWriter::new(file),
        )
        .map_err(|e| describe(&e))?;
        let store = StoreId::random(StoreKind::Recording, "uavex");
        let info = StoreInfo::new(store.clone(), StoreSource::Other("uavex".to_owned()));
        encoder
            .append(&LogMsg::SetStoreInfo(SetStoreInfo {
                row_id: *RowId::new(),
                info,
            }))
            .map_err(|e| describe(&e))?;
        let mut writer = Self {
            encoder,
            store,
            pending: BTreeMap::new(),
            error: None,
            path: path.to_owned(),
        };
        writer.log_static(
            &EntityPath::properties(),
            &RecordingInfo::new().with_name(name),
        );
        Ok(writer)
    }

    /// Logs `archetype` at `entity` at simulated time `time_s`.
    pub fn log(&mut self, entity: &EntityPath, time_s: f64, archetype: &dyn AsComponents) {
        let nanos = (time_s * 1e9).round() as i64;
        let time = TimePoint::from([(SIM_TIME, TimeCell::from_duration_nanos(nanos))]);
        let pending = self
            .pending
            .entry(entity.clone())
            .or_insert_with(|| PendingChunk {
                builder: Chunk::builder(entity.clone()),
                rows: 0,
            });
        let builder = std::mem::replace(&mut pending.builder, Chunk::builder(entity.clone()));
        pending.builder = builder.with_archetype(RowId::new(), time, archetype);
        pending.rows += 1;
        if pending.rows >= ROWS_PER_CHUNK {
            self.flush(entity);
        }
    }

    /// Logs `archetype` at `entity` for all times (what does not change during a run).
    pub fn log_static(&mut self, entity: &EntityPath, archetype: &dyn AsComponents) {
        // A chunk is either static or temporal: static rows are written on their own at once.
        let chunk = Chunk::builder(entity.clone())
            .with_archetype(RowId::new(), TimePoint::default(), archetype)
            .build();
        self.write(chunk);
    }

    /// Writes every pending row, closes the stream and returns the file's size (bytes).
    pub fn finish(mut self) -> Result<u64, String> {
        let entities: Vec<EntityPath> = self.pending.keys().cloned().collect();
        for entity in &entities {
            self.flush(entity);
        }
        if let Some(error) = self.error.take() {
            return Err(error);
        }
        let path = self.path.clone();
        let describe = |e: &dyn std::fmt::Display| format!("{}: {e}", path.display());
        self.encoder.finish().map_err(|e| describe(&e))?;
        let mut file = self.encoder.into_inner().map_err(|e| describe(&e))?;
        file.flush().map_err(|e| describe(&e))?;
        let file = file.into_inner().map_err(|e| describe(e.error()))?;
        file.sync_all().map_err(|e| describe(&e))?;
        file.metadata().map(|m| m.len()).map_err(|e| describe(&e))
    }

    fn flush(&mut self, entity: &EntityPath) {
        if let Some(pending) = self.pending.remove(entity) {
            self.write(pending.builder.build());
        }
    }

    fn write(&mut self, chunk: re_chunk::ChunkResult<Chunk>) {
        if self.error.is_some() {
            return;
        }
        let written = chunk
            .and_then(|chunk| chunk.to_arrow_msg())
            .map_err(|e| e.to_string())
            .and_then(|msg| {
                self.encoder
                    .append(&LogMsg::ArrowMsg(self.store.clone(), msg))
                    .map_err(|e| e.to_string())
            });
        if let Err(e) = written {
            self.error = Some(format!("{}: {e}", self.path.display()));
        }
    }
}

/// Several archetypes logged as one row of one entity (strips with the numbers behind them).
pub struct Together<'a>(pub &'a [&'a dyn AsComponents]);

impl AsComponents for Together<'_> {
    fn as_serialized_batches(&self) -> Vec<re_sdk_types::SerializedComponentBatch> {
        self.0
            .iter()
            .flat_map(|part| part.as_serialized_batches())
            .collect()
    }
}
