//! A small Leica LIF writer for tests: one project element holding one image of 8-bit channels,
//! its dimensions given as `(DimID, NumberOfElements, Length, BytesInc)` (Length in s for
//! time, DimID 4, else in m). Written from the
//! layout our reader (`crates/formats/src/microscopy/lif.rs`) documents: the `0x70` header block
//! with the UTF-16LE XML, then one version-2 memory block (u64 size) with the pixel data. Never
//! a copy of a real sample (the real LIF sample is GPL-3.0).

/// One dimension: `DimID`, `NumberOfElements`, `Length` (s for DimID 4, else m), `BytesInc`.
pub type Dim = (u32, usize, f64, usize);

fn utf16(s: &str) -> Vec<u8> {
    s.encode_utf16().flat_map(u16::to_le_bytes).collect()
}

/// A LIF file holding image `name` with `channels` 8-bit channels at the given byte offsets
/// within the memory block `data`.
pub fn lif(name: &str, dims: &[Dim], channel_offsets: &[usize], data: &[u8]) -> Vec<u8> {
    let channels: String = channel_offsets
        .iter()
        .map(|o| format!(r#"<ChannelDescription DataType="0" Resolution="8" BytesInc="{o}"/>"#))
        .collect();
    let dimensions: String = dims
        .iter()
        .map(|(id, n, len, inc)| {
            // Time (DimID 4) is in seconds, every other dimension in metres.
            let unit = if *id == 4 { "s" } else { "m" };
            format!(
                r#"<DimensionDescription DimID="{id}" NumberOfElements="{n}" Length="{len:e}" Unit="{unit}" BytesInc="{inc}"/>"#
            )
        })
        .collect();
    let xml = format!(
        r#"<LMSDataContainerHeader Version="2"><Element Name="project"><Data><Experiment/></Data><Memory MemoryBlockID="MemBlock_0" Size="0"/><Children><Element Name="{name}"><Data><Image><ImageDescription><Channels>{channels}</Channels><Dimensions>{dimensions}</Dimensions></ImageDescription></Image></Data><Memory MemoryBlockID="MemBlock_1" Size="{}"/><Children/></Element></Children></Element></LMSDataContainerHeader>"#,
        data.len()
    );
    let xml = utf16(&xml);
    let mut file = 0x70u32.to_le_bytes().to_vec();
    file.extend(((5 + xml.len()) as u32).to_le_bytes());
    file.push(0x2a);
    file.extend(((xml.len() / 2) as u32).to_le_bytes());
    file.extend(&xml);
    for (id, block) in [("MemBlock_0", &[][..]), ("MemBlock_1", data)] {
        file.extend(0x70u32.to_le_bytes());
        file.extend(0u32.to_le_bytes());
        file.push(0x2a);
        file.extend((block.len() as u64).to_le_bytes());
        file.push(0x2a);
        file.extend((id.len() as u32).to_le_bytes());
        file.extend(utf16(id));
        file.extend(block);
    }
    file
}
