// rsg-mcap-check: checks an MCAP file with MCAP's own Go library (github.com/foxglove/mcap/go/mcap,
// the library the official `mcap` CLI is built on), for the tests in tests/tools/record/. The official
// CLI itself (`mcap doctor`, `mcap info`) is not served by the Go module proxy (see
// docs/mcap-tested.md), so this program applies the rules of the MCAP specification that `mcap
// doctor` applies, and a few more, using the library's lexer and parsers for every byte it reads.
//
//	rsg-mcap-check doctor FILE   problems as "error: ..." / "warning: ..." lines; exit 1 on any error
//	rsg-mcap-check info FILE     the summary as the library's indexed reader sees it, as JSON
//
// Written for rsg; no code of the CLI is copied here.
package main

import (
	"bytes"
	"encoding/json"
	"errors"
	"fmt"
	"hash/crc32"
	"io"
	"math"
	"os"
	"reflect"
	"sort"
	"unicode/utf8"

	"github.com/foxglove/mcap/go/mcap"
)

// The first 9 bytes of a record: opcode and uint64 content length.
const recordPrefix = 9

type doctor struct {
	file     []byte
	errors   []string
	warnings []string

	schemas        map[uint16]*mcap.Schema // data section
	channels       map[uint16]*mcap.Channel
	summarySchemas map[uint16]*mcap.Schema
	summaryChans   map[uint16]*mcap.Channel
	inSummary      bool

	chunks       map[uint64]*chunkSeen // by the chunk record's offset
	lastChunk    *chunkSeen            // message indexes follow their chunk
	chunkIndexes []*mcap.ChunkIndex
	statistics   *mcap.Statistics
	summaryOffs  []*mcap.SummaryOffset
	dataEnd      *mcap.DataEnd
	dataEndAt    uint64
	footer       *mcap.Footer
	summaryAt    uint64 // offset of the first record after Data End

	messages      uint64
	perChannel    map[uint16]uint64
	minTime       uint64
	maxTime       uint64
	lastTime      uint64
	outOfOrder    uint64
	outsideChunks uint64
}

type messageAt struct {
	channel uint16
	logTime uint64
}

type chunkSeen struct {
	offset, length uint64
	chunk          *mcap.Chunk
	messages       map[uint64]messageAt // offset in the uncompressed records -> message
	indexed        map[uint16]bool      // channels with a Message Index record after the chunk
	indexesEnd     uint64
	indexOffsets   map[uint16]uint64
}

func (d *doctor) errorf(format string, args ...any) {
	d.errors = append(d.errors, fmt.Sprintf(format, args...))
}

func (d *doctor) warnf(format string, args ...any) {
	d.warnings = append(d.warnings, fmt.Sprintf(format, args...))
}

func validUTF8(d *doctor, what string, values ...string) {
	for _, value := range values {
		if !utf8.ValidString(value) {
			d.errorf("%s is not valid UTF-8: %q", what, value)
		}
	}
}

func (d *doctor) schema(s *mcap.Schema) {
	validUTF8(d, fmt.Sprintf("schema %d name/encoding", s.ID), s.Name, s.Encoding)
	if s.ID == 0 {
		d.errorf("a schema has the reserved id 0")
	}
	if s.Encoding == "" && len(s.Data) > 0 {
		d.errorf("schema %d has data but no encoding", s.ID)
	}
	if s.Encoding == "" && len(s.Data) == 0 {
		d.warnf("schema %d (%q) has neither encoding nor data", s.ID, s.Name)
	}
	define(d, "schema", s.ID, s, d.schemas, d.summarySchemas)
}

// define records a schema or channel: one in the summary must repeat the data section's, one written
// twice in the data section must be the same (a warning even then, as `mcap doctor` gives).
func define[T any](d *doctor, kind string, id uint16, record *T, data, summary map[uint16]*T) {
	previous := data[id]
	if d.inSummary {
		if previous == nil {
			d.errorf("%s %d is in the summary but not in the data section", kind, id)
		} else if !reflect.DeepEqual(previous, record) {
			d.errorf("%s %d in the summary differs from the data section's", kind, id)
		}
		summary[id] = record
		return
	}
	if previous != nil {
		if !reflect.DeepEqual(previous, record) {
			d.errorf("two different %s records with id %d", kind, id)
		} else {
			d.warnf("%s %d is written twice in the data section", kind, id)
		}
	}
	data[id] = record
}

func (d *doctor) channel(c *mcap.Channel) {
	validUTF8(d, fmt.Sprintf("channel %d topic/encoding", c.ID), c.Topic, c.MessageEncoding)
	for key, value := range c.Metadata {
		validUTF8(d, fmt.Sprintf("channel %d metadata", c.ID), key, value)
	}
	if c.SchemaID != 0 && d.schemas[c.SchemaID] == nil {
		d.errorf("channel %d (%s) names schema %d, which comes later or never", c.ID, c.Topic, c.SchemaID)
	}
	define(d, "channel", c.ID, c, d.channels, d.summaryChans)
}

func (d *doctor) message(m *mcap.Message) {
	channel := d.channels[m.ChannelID]
	if channel == nil {
		d.errorf("a message on channel %d comes before that channel's record", m.ChannelID)
	}
	if m.LogTime < d.lastTime {
		if d.outOfOrder == 0 {
			topic := ""
			if channel != nil {
				topic = channel.Topic
			}
			d.warnf("message log_time %d on %q is before the previous message's %d (first of the messages out of order)",
				m.LogTime, topic, d.lastTime)
		}
		d.outOfOrder++
	}
	d.lastTime = max(d.lastTime, m.LogTime)
	d.minTime = min(d.minTime, m.LogTime)
	d.maxTime = max(d.maxTime, m.LogTime)
	d.messages++
	d.perChannel[m.ChannelID]++
}

// chunk decompresses a chunk with the library's own lexer (which checks its CRC) and looks at every record in it.
func (d *doctor) chunk(c *mcap.Chunk, offset, length uint64) {
	seen := &chunkSeen{offset: offset, length: length, chunk: c, messages: map[uint64]messageAt{},
		indexed: map[uint16]bool{}, indexOffsets: map[uint16]uint64{}}
	d.chunks[offset] = seen
	d.lastChunk = seen
	// A one-chunk MCAP stream without magic: the lexer decompresses and checks it as it would in a file.
	var wrapped bytes.Buffer
	wrapped.WriteByte(byte(mcap.OpChunk))
	var lengthBytes [8]byte
	contentLength := length - recordPrefix
	for i := range lengthBytes {
		lengthBytes[i] = byte(contentLength >> (8 * i))
	}
	wrapped.Write(lengthBytes[:])
	wrapped.Write(d.file[offset+recordPrefix : offset+length])
	lexer, err := mcap.NewLexer(&wrapped, &mcap.LexerOptions{SkipMagic: true, ValidateChunkCRCs: true})
	if err != nil {
		d.errorf("chunk at %d: %v", offset, err)
		return
	}
	defer lexer.Close()
	// Offsets inside the uncompressed records, from the records' own lengths.
	var at uint64
	var first, last uint64 = math.MaxUint64, 0
	count := 0
	for {
		token, data, err := lexer.Next(nil)
		if errors.Is(err, io.EOF) {
			break
		}
		if err != nil {
			d.errorf("chunk at %d does not read: %v", offset, err)
			return
		}
		here := at
		at += recordPrefix + uint64(len(data))
		switch token {
		case mcap.TokenSchema:
			if s, err := mcap.ParseSchema(data); err != nil {
				d.errorf("chunk at %d: a schema does not parse: %v", offset, err)
			} else {
				d.schema(s)
			}
		case mcap.TokenChannel:
			if ch, err := mcap.ParseChannel(data); err != nil {
				d.errorf("chunk at %d: a channel does not parse: %v", offset, err)
			} else {
				d.channel(ch)
			}
		case mcap.TokenMessage:
			m, err := mcap.ParseMessage(data)
			if err != nil {
				d.errorf("chunk at %d: a message does not parse: %v", offset, err)
				continue
			}
			d.message(m)
			seen.messages[here] = messageAt{m.ChannelID, m.LogTime}
			first, last = min(first, m.LogTime), max(last, m.LogTime)
			count++
		default:
			d.errorf("chunk at %d holds a %s record, which a chunk may not", offset, token)
		}
	}
	if at != c.UncompressedSize {
		d.errorf("chunk at %d: its records take %d bytes, it claims %d", offset, at, c.UncompressedSize)
	}
	if count > 0 && (first != c.MessageStartTime || last != c.MessageEndTime) {
		d.errorf("chunk at %d says its messages span [%d, %d]; they span [%d, %d]", offset,
			c.MessageStartTime, c.MessageEndTime, first, last)
	}
	if count == 0 {
		d.warnf("chunk at %d holds no message", offset)
	}
}

func (d *doctor) messageIndex(index *mcap.MessageIndex, offset, length uint64) {
	c := d.lastChunk
	if c == nil {
		d.errorf("a message index at %d follows no chunk", offset)
		return
	}
	if c.indexed[index.ChannelID] {
		d.errorf("chunk at %d has two message indexes for channel %d", c.offset, index.ChannelID)
	}
	c.indexed[index.ChannelID] = true
	c.indexOffsets[index.ChannelID] = offset
	c.indexesEnd = offset + length
	entries := 0
	for _, entry := range index.Records {
		message, ok := c.messages[entry.Offset]
		if !ok || message.channel != index.ChannelID || message.logTime != entry.Timestamp {
			d.errorf("message index of channel %d after chunk %d points at %d, where no message of that "+
				"channel with log time %d starts", index.ChannelID, c.offset, entry.Offset, entry.Timestamp)
			return
		}
		entries++
	}
	want := 0
	for _, message := range c.messages {
		if message.channel == index.ChannelID {
			want++
		}
	}
	if entries != want {
		d.errorf("message index of channel %d after chunk %d lists %d messages of the chunk's %d",
			index.ChannelID, c.offset, entries, want)
	}
}

// checkIndexes compares the summary (chunk indexes, statistics) with what the data section holds.
func (d *doctor) checkIndexes() {
	indexedChunks := map[uint64]bool{}
	for _, index := range d.chunkIndexes {
		c := d.chunks[index.ChunkStartOffset]
		if c == nil {
			d.errorf("a chunk index points at %d, where no chunk starts", index.ChunkStartOffset)
			continue
		}
		if indexedChunks[c.offset] {
			d.errorf("two chunk indexes for the chunk at %d", c.offset)
		}
		indexedChunks[c.offset] = true
		switch {
		case index.ChunkLength != c.length:
			d.errorf("chunk index for %d: length %d, the record has %d", c.offset, index.ChunkLength, c.length)
		case index.MessageStartTime != c.chunk.MessageStartTime || index.MessageEndTime != c.chunk.MessageEndTime:
			d.errorf("chunk index for %d: times differ from the chunk's", c.offset)
		case string(index.Compression) != c.chunk.Compression:
			d.errorf("chunk index for %d: compression %q, the chunk %q", c.offset, index.Compression, c.chunk.Compression)
		case index.CompressedSize != uint64(len(c.chunk.Records)) || index.UncompressedSize != c.chunk.UncompressedSize:
			d.errorf("chunk index for %d: sizes differ from the chunk's", c.offset)
		case !reflect.DeepEqual(index.MessageIndexOffsets, c.indexOffsets):
			d.errorf("chunk index for %d: message index offsets %v, the file has %v", c.offset,
				index.MessageIndexOffsets, c.indexOffsets)
		case len(c.indexOffsets) > 0 && index.MessageIndexLength != c.indexesEnd-c.offset-c.length:
			d.errorf("chunk index for %d: message index length %d, the file has %d", c.offset,
				index.MessageIndexLength, c.indexesEnd-c.offset-c.length)
		}
		for _, message := range c.messages {
			channel := d.channels[message.channel]
			if channel == nil {
				continue
			}
			if d.summaryChans[message.channel] == nil {
				d.errorf("indexed chunk at %d has messages of channel %d, which the summary lacks", c.offset, message.channel)
			}
			if channel.SchemaID != 0 && d.summarySchemas[channel.SchemaID] == nil {
				d.errorf("indexed chunk at %d has messages of schema %d, which the summary lacks", c.offset, channel.SchemaID)
			}
		}
	}
	if len(d.chunkIndexes) > 0 {
		for offset, c := range d.chunks {
			if !indexedChunks[offset] {
				d.errorf("the chunk at %d has no chunk index: indexed readers miss its %d messages", offset, len(c.messages))
			}
			for channel := range messageChannels(c) {
				if !c.indexed[channel] {
					d.errorf("the chunk at %d has no message index for channel %d", offset, channel)
				}
			}
		}
		if d.outsideChunks > 0 {
			d.warnf("%d messages are outside chunks: indexed readers miss them", d.outsideChunks)
		}
	}
	if s := d.statistics; s != nil {
		if s.MessageCount != d.messages {
			d.errorf("statistics count %d messages; the file has %d", s.MessageCount, d.messages)
		}
		if d.messages > 0 && (s.MessageStartTime != d.minTime || s.MessageEndTime != d.maxTime) {
			d.errorf("statistics say the messages span [%d, %d]; they span [%d, %d]", s.MessageStartTime,
				s.MessageEndTime, d.minTime, d.maxTime)
		}
		if int(s.SchemaCount) != len(d.schemas) || int(s.ChannelCount) != len(d.channels) ||
			int(s.ChunkCount) != len(d.chunks) {
			d.errorf("statistics count %d schemas, %d channels, %d chunks; the file has %d, %d, %d", s.SchemaCount,
				s.ChannelCount, s.ChunkCount, len(d.schemas), len(d.channels), len(d.chunks))
		}
		for id := range d.channels {
			if s.ChannelMessageCounts[id] != d.perChannel[id] {
				d.errorf("statistics count %d messages on channel %d; the file has %d", s.ChannelMessageCounts[id],
					id, d.perChannel[id])
			}
		}
	}
}

func messageChannels(c *chunkSeen) map[uint16]bool {
	channels := map[uint16]bool{}
	for _, message := range c.messages {
		channels[message.channel] = true
	}
	return channels
}

// checkCRCs: the Data End record's CRC covers every byte before it, the footer's the summary
// section up to its own summary_crc field (both may be 0: not computed).
func (d *doctor) checkCRCs() {
	if d.dataEnd != nil && d.dataEnd.DataSectionCRC != 0 {
		if crc := crc32.ChecksumIEEE(d.file[:d.dataEndAt]); crc != d.dataEnd.DataSectionCRC {
			d.errorf("data section CRC %08x, the bytes give %08x", d.dataEnd.DataSectionCRC, crc)
		}
	}
	if f := d.footer; f != nil && f.SummaryCRC != 0 {
		start := f.SummaryStart
		if start == 0 {
			start = f.SummaryOffsetStart
		}
		end := uint64(len(d.file)) - 8 - 4 // magic, summary_crc
		if start == 0 || start > end {
			d.errorf("the footer's summary start %d is outside the file", start)
		} else if crc := crc32.ChecksumIEEE(d.file[start:end]); crc != f.SummaryCRC {
			d.errorf("summary CRC %08x, the bytes give %08x", f.SummaryCRC, crc)
		}
	}
	if f := d.footer; f != nil && f.SummaryStart != 0 && f.SummaryStart != d.summaryAt {
		d.errorf("the footer says the summary starts at %d; it starts at %d", f.SummaryStart, d.summaryAt)
	}
	for _, group := range d.summaryOffs {
		if group.GroupStart+group.GroupLength > uint64(len(d.file)) || group.GroupStart < d.summaryAt {
			d.errorf("a summary offset for opcode %d points outside the summary", group.GroupOpcode)
			continue
		}
		lexer, err := mcap.NewLexer(bytes.NewReader(d.file[group.GroupStart:group.GroupStart+group.GroupLength]),
			&mcap.LexerOptions{SkipMagic: true})
		if err != nil {
			d.errorf("summary offset group %d: %v", group.GroupOpcode, err)
			continue
		}
		for {
			token, data, err := lexer.Next(nil)
			if errors.Is(err, io.EOF) {
				break
			}
			if err != nil || opcodeOf(token) != group.GroupOpcode {
				d.errorf("the summary offset group of opcode %d holds other records (%s, %v)", group.GroupOpcode, token, err)
				break
			}
			_ = data
		}
		lexer.Close()
	}
}

func opcodeOf(token mcap.TokenType) mcap.OpCode {
	return map[mcap.TokenType]mcap.OpCode{
		mcap.TokenSchema: mcap.OpSchema, mcap.TokenChannel: mcap.OpChannel, mcap.TokenChunkIndex: mcap.OpChunkIndex,
		mcap.TokenStatistics: mcap.OpStatistics, mcap.TokenAttachmentIndex: mcap.OpAttachmentIndex,
		mcap.TokenMetadataIndex: mcap.OpMetadataIndex,
	}[token]
}

func (d *doctor) examine() {
	reader := bytes.NewReader(d.file)
	lexer, err := mcap.NewLexer(reader, &mcap.LexerOptions{EmitChunks: true})
	if err != nil {
		d.errorf("not an MCAP file: %v", err)
		return
	}
	defer lexer.Close()
	for {
		token, data, err := lexer.Next(nil)
		if errors.Is(err, io.EOF) {
			break
		}
		if err != nil {
			d.errorf("the file does not read on at byte %d: %v", int64(len(d.file))-int64(reader.Len()), err)
			return
		}
		end := uint64(len(d.file) - reader.Len())
		offset := end - recordPrefix - uint64(len(data))
		fail := func(err error) bool {
			if err != nil {
				d.errorf("the %s record at %d does not parse: %v", token, offset, err)
			}
			return err != nil
		}
		switch token {
		case mcap.TokenHeader:
			h, err := mcap.ParseHeader(data)
			if fail(err) {
				continue
			}
			validUTF8(d, "the header", h.Profile, h.Library)
			if h.Library == "" {
				d.warnf("the header names no library")
			}
			if h.Profile != "" && h.Profile != "ros1" && h.Profile != "ros2" {
				d.warnf("header profile %q is not a well-known profile", h.Profile)
			}
		case mcap.TokenSchema:
			if s, err := mcap.ParseSchema(data); !fail(err) {
				d.schema(s)
			}
		case mcap.TokenChannel:
			if c, err := mcap.ParseChannel(data); !fail(err) {
				d.channel(c)
			}
		case mcap.TokenMessage:
			if m, err := mcap.ParseMessage(data); !fail(err) {
				d.message(m)
				d.outsideChunks++
			}
		case mcap.TokenChunk:
			if c, err := mcap.ParseChunk(data); !fail(err) {
				d.chunk(c, offset, end-offset)
			}
		case mcap.TokenMessageIndex:
			if index, err := mcap.ParseMessageIndex(data); !fail(err) {
				d.messageIndex(index, offset, end-offset)
			}
		case mcap.TokenChunkIndex:
			if index, err := mcap.ParseChunkIndex(data); !fail(err) {
				d.chunkIndexes = append(d.chunkIndexes, index)
			}
		case mcap.TokenStatistics:
			s, err := mcap.ParseStatistics(data)
			if !fail(err) {
				if d.statistics != nil {
					d.errorf("two statistics records")
				}
				d.statistics = s
			}
		case mcap.TokenSummaryOffset:
			if s, err := mcap.ParseSummaryOffset(data); !fail(err) {
				d.summaryOffs = append(d.summaryOffs, s)
			}
		case mcap.TokenDataEnd:
			if e, err := mcap.ParseDataEnd(data); !fail(err) {
				d.dataEnd, d.dataEndAt, d.summaryAt, d.inSummary = e, offset, end, true
			}
		case mcap.TokenFooter:
			if f, err := mcap.ParseFooter(data); !fail(err) {
				d.footer = f
			}
		}
	}
	if d.dataEnd == nil {
		d.errorf("the file has no Data End record")
	}
	if d.footer == nil {
		d.errorf("the file has no footer")
	}
	if d.outOfOrder > 0 {
		d.warnf("%d messages have a log time before an earlier message's", d.outOfOrder)
	}
	d.checkIndexes()
	d.checkCRCs()
}

type channelInfo struct {
	ID              uint16            `json:"id"`
	Topic           string            `json:"topic"`
	MessageEncoding string            `json:"message_encoding"`
	Schema          string            `json:"schema"`
	SchemaEncoding  string            `json:"schema_encoding"`
	Metadata        map[string]string `json:"metadata"`
	Messages        uint64            `json:"messages"`
	IndexedMessages uint64            `json:"indexed_messages"`
}

// info reads the file as the library's indexed reader does (the summary, then every message
// through the chunk and message indexes) and prints what it found.
func info(path string) error {
	file, err := os.Open(path)
	if err != nil {
		return err
	}
	defer file.Close()
	reader, err := mcap.NewReader(file)
	if err != nil {
		return err
	}
	summary, err := reader.Info()
	if err != nil {
		return err
	}
	if summary.Statistics == nil {
		return fmt.Errorf("the summary has no statistics")
	}
	channels := []channelInfo{}
	for id, channel := range summary.Channels {
		entry := channelInfo{ID: id, Topic: channel.Topic, MessageEncoding: channel.MessageEncoding,
			Metadata: channel.Metadata, Messages: summary.Statistics.ChannelMessageCounts[id]}
		if schema := summary.Schemas[channel.SchemaID]; schema != nil {
			entry.Schema, entry.SchemaEncoding = schema.Name, schema.Encoding
		}
		channels = append(channels, entry)
	}
	sort.Slice(channels, func(i, j int) bool { return channels[i].ID < channels[j].ID })
	iterator, err := reader.Messages(mcap.UsingIndex(true), mcap.InOrder(mcap.LogTimeOrder))
	if err != nil {
		return err
	}
	var read uint64
	for {
		_, channel, _, err := iterator.NextInto(nil)
		if errors.Is(err, io.EOF) {
			break
		}
		if err != nil {
			return fmt.Errorf("reading messages through the index: %w", err)
		}
		read++
		for i := range channels {
			if channels[i].ID == channel.ID {
				channels[i].IndexedMessages++
			}
		}
	}
	compression := map[string]int{}
	for _, index := range summary.ChunkIndexes {
		compression[string(index.Compression)]++
	}
	return json.NewEncoder(os.Stdout).Encode(map[string]any{
		"library":          summary.Header.Library,
		"profile":          summary.Header.Profile,
		"messages":         summary.Statistics.MessageCount,
		"indexed_messages": read,
		"start":            summary.Statistics.MessageStartTime,
		"end":              summary.Statistics.MessageEndTime,
		"chunks":           len(summary.ChunkIndexes),
		"compression":      compression,
		"schemas":          len(summary.Schemas),
		"channels":         channels,
	})
}

func main() {
	if len(os.Args) != 3 || (os.Args[1] != "doctor" && os.Args[1] != "info") {
		fmt.Fprintln(os.Stderr, "usage: rsg-mcap-check doctor|info FILE")
		os.Exit(2)
	}
	if os.Args[1] == "info" {
		if err := info(os.Args[2]); err != nil {
			fmt.Fprintf(os.Stderr, "rsg-mcap-check info: %v\n", err)
			os.Exit(1)
		}
		return
	}
	file, err := os.ReadFile(os.Args[2])
	if err != nil {
		fmt.Fprintf(os.Stderr, "rsg-mcap-check: %v\n", err)
		os.Exit(1)
	}
	d := &doctor{file: file, schemas: map[uint16]*mcap.Schema{}, channels: map[uint16]*mcap.Channel{},
		summarySchemas: map[uint16]*mcap.Schema{}, summaryChans: map[uint16]*mcap.Channel{},
		chunks: map[uint64]*chunkSeen{}, perChannel: map[uint16]uint64{}, minTime: math.MaxUint64}
	d.examine()
	for _, warning := range d.warnings {
		fmt.Println("warning:", warning)
	}
	for _, e := range d.errors {
		fmt.Println("error:", e)
	}
	fmt.Printf("%d errors, %d warnings; %d messages in %d chunks\n", len(d.errors), len(d.warnings), d.messages, len(d.chunks))
	if len(d.errors) > 0 {
		os.Exit(1)
	}
}
